#!/usr/bin/env python3
"""Sums the kernel times of a CubeCL profile log (`CUBECL_DEBUG_OPTION=profile`, as
`scripts/gpu-profile.sh` writes it; plain or .gz) per kernel, largest first.

  scripts/cubecl-profile-summary.py LOG [TOP]
"""
import collections, gzip, re, sys

UNITS = {"ns": 1e-9, "µs": 1e-6, "us": 1e-6, "ms": 1e-3, "s": 1.0}
LINE = re.compile(r"^\|\s*([0-9.]+)(ns|µs|us|ms|s)\s*\|\s*([^|]+?)\s*(\||$)")


def main():
    path, top = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 15
    opener = gzip.open if path.endswith(".gz") else open
    total, count, longest = collections.Counter(), collections.Counter(), {}
    with opener(path, "rt", encoding="utf-8", errors="replace") as f:
        for line in f:
            m = LINE.match(line)
            if not m:
                continue
            seconds = float(m.group(1)) * UNITS[m.group(2)]
            name = m.group(3).split("<")[0].strip()
            total[name] += seconds
            count[name] += 1
            longest[name] = max(longest.get(name, 0.0), seconds)
    whole = sum(total.values())
    if whole == 0:
        sys.exit(f"{path}: no profiled kernel launches (was CUBECL_DEBUG_OPTION=profile set?)")
    print(f"{whole:.3f} s of kernel time in {sum(count.values())} launches ({path})")
    print(f"{'seconds':>8} {'share':>6} {'launches':>8} {'longest':>9}  kernel")
    for name, seconds in total.most_common(top):
        print(f"{seconds:8.3f} {100 * seconds / whole:5.1f}% {count[name]:8d} {longest[name]:8.3f}s  {name}")


if __name__ == "__main__":
    main()
