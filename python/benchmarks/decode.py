"""The cost of decoding through Python: `Model.decode` (the library's decode, its invalid cells
set to NaN in place, then one copy into a new numpy array) against the library's own decode
(`Model.library_decode_seconds`: `DeepBrdf::decode`, no array made), on the shipped model.

    RAYON_NUM_THREADS=2 python python/benchmarks/decode.py [--repeats 50]

The two alternate (which goes first alternates too, so that the allocator's and the machine's
state weigh on both alike). Prints the medians of wall-clock time and of the process's CPU
time (all threads), and their ratios; the target is at most 1.1.
"""
import argparse
import os
import statistics
import time

import deepbrdf


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=50, help="decodes timed each way")
    parser.add_argument("--material", default="chrome", help="the bundled material encoded")
    args = parser.parse_args()
    model = deepbrdf.Model.load()
    latent = model.encode(deepbrdf.bundled(args.material))
    model.decode(latent)  # warm-up: the first call sets up the backend
    calls = {
        "python": lambda: model.decode(latent),
        "library": lambda: model.library_decode_seconds(latent, 1),
    }
    wall = {name: [] for name in calls}
    cpu = {name: [] for name in calls}
    for i in range(args.repeats):
        order = ["python", "library"] if i % 2 == 0 else ["library", "python"]
        for name in order:
            start_wall, start_cpu = time.perf_counter(), time.process_time()
            calls[name]()
            wall[name].append(time.perf_counter() - start_wall)
            cpu[name].append(time.process_time() - start_cpu)
    median = {k: {n: statistics.median(v[n]) for n in calls} for k, v in (("wall", wall), ("cpu", cpu))}
    print(
        f"model {model.id} (k = {model.k}), {args.repeats} decodes of {args.material}'s latent "
        f"each way, RAYON_NUM_THREADS={os.environ.get('RAYON_NUM_THREADS', 'unset')}, "
        f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs"
    )
    for kind in ("wall", "cpu"):
        lib, py = median[kind]["library"], median[kind]["python"]
        print(f"{kind:4} time (median): library {lib * 1e3:.2f} ms, Python {py * 1e3:.2f} ms, ratio {py / lib:.3f}")


if __name__ == "__main__":
    main()
