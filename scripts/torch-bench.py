"""PyTorch's Table 1 (torch_table1.py, from ../shared/bench, copied into the GPU bundle) timed on a
CUDA GPU in both of its precisions, one after the other in one process: strict f32 (TF32 off for
convolutions and matrix products, as Burn computes) and PyTorch's default (TF32 convolutions).

  python3 scripts/torch-bench.py BUNDLE/torch_table1.py [BATCHES]   # BATCHES default 1,32

Used by scripts/gpu-run.sh and scripts/gpu-profile.sh (docs/gpu.md).
"""
import runpy
import sys

import torch

script = sys.argv[1]
batches = sys.argv[2] if len(sys.argv) > 2 else "1,32"
for label, tf32 in (("strict f32 (TF32 off)", False), ("PyTorch default (TF32 convolutions)", True)):
    torch.backends.cudnn.allow_tf32 = tf32
    torch.backends.cuda.matmul.allow_tf32 = False
    print(f"== PyTorch Table 1, {label}", flush=True)
    for mode in (["--mode", "train", "--batch", batches, "--steps", "12"], ["--mode", "decode", "--steps", "20"]):
        sys.argv = [script, "--device", "cuda", *mode]
        runpy.run_path(script, run_name="__main__")
