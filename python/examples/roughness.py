"""Load a bundled material, double its roughness with the shipped DeepBRDF model, render both and
save them side by side as a PNG (docs/python.md).

    python python/examples/roughness.py side-by-side.png
"""
import argparse

import numpy as np

import deepbrdf

parser = argparse.ArgumentParser(description="a roughness edit, rendered before and after")
parser.add_argument("output", help="the PNG to write")
parser.add_argument("--material", default="gold-metallic-paint")
parser.add_argument("--roughness-scale", type=float, default=2.0)
parser.add_argument("--size", type=int, default=256)
parser.add_argument("--spp", type=int, default=64)
args = parser.parse_args()

table = deepbrdf.bundled(args.material)  # an NBRDF fit of MERL, tabulated on the MERL grid
model = deepbrdf.Model.load()  # the shipped model, models/default
edited = model.edit(table, roughness_scale=args.roughness_scale)
print("attributes before:", np.round(deepbrdf.attributes(table), 4))
print("attributes after: ", np.round(deepbrdf.attributes(edited), 4))

before = deepbrdf.render(table, size=args.size, spp=args.spp)
after = deepbrdf.render(edited, size=args.size, spp=args.spp)
deepbrdf.write_png(args.output, np.concatenate([before, after], axis=1))
print("wrote", args.output)
