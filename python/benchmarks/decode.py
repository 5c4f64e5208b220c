"""The cost of decoding through Python: `Model.decode` (the library's decode, then the one copy
into the returned numpy array with invalid cells as NaN) against the library's own decode time
(`Model.library_decode_seconds`, the same decode with no array made), on the shipped model.

    RAYON_NUM_THREADS=2 python python/benchmarks/decode.py [--repeats 30]

Prints the median of each and their ratio (the target is at most 1.1).
"""
import argparse
import statistics
import time

import deepbrdf


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30, help="decodes timed each way")
    parser.add_argument("--material", default="chrome", help="the bundled material encoded")
    args = parser.parse_args()
    model = deepbrdf.Model.load()
    latent = model.encode(deepbrdf.bundled(args.material))
    model.decode(latent)  # warm-up: the first call sets up the backend
    python = []
    library = []
    # Interleaved, so that the machine's load weighs on both alike.
    for _ in range(args.repeats):
        start = time.perf_counter()
        model.decode(latent)
        python.append(time.perf_counter() - start)
        library.extend(model.library_decode_seconds(latent, 1))
    py_median = statistics.median(python)
    lib_median = statistics.median(library)
    print(f"model {model.id} (k = {model.k}), {args.repeats} decodes of {args.material}'s latent each way")
    print(f"library decode (median): {lib_median * 1e3:.2f} ms")
    print(f"Python decode  (median): {py_median * 1e3:.2f} ms")
    print(f"ratio: {py_median / lib_median:.3f}")


if __name__ == "__main__":
    main()
