#!/usr/bin/env python3
"""Renders an RGL .bsdf file with Mitsuba 3's own `measured` BSDF (variant scalar_rgb) in the
scene `experiments render --shape sphere --light dir:THETA,PHI --view THETA,PHI` renders: a unit
sphere at the origin, an orthographic camera framing it with a 4% margin (image up = the
projection of +z), one directional light of irradiance pi, direct illumination, a box pixel
filter. Writes linear RGB and coverage (alpha) as OpenEXR, as `render --exr` does, so the two
images compare pixel for pixel (tests/cli/mitsuba.rs, docs/data.md).

  scripts/mitsuba-render.py FILE.bsdf OUT.exr [--size 64] [--spp 64] [--seed 0]
                            [--light THETA,PHI] [--view THETA,PHI]
"""
import argparse
import math
import sys


def spherical(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return [math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]


def pair(text):
    a, b = text.split(",")
    return float(a), float(b)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bsdf")
    ap.add_argument("out")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--light", type=pair, default=(45.0, 30.0))
    ap.add_argument("--view", type=pair, default=(70.0, 0.0))
    args = ap.parse_args()

    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    # The project's camera: distance 2 * framed + 1, half side `framed`, radius 1 + 4% margin.
    framed = 1.04
    towards = spherical(*args.view)
    if abs(towards[2]) > 1.0 - 1e-9:
        raise SystemExit("a view straight down or up is not supported here")
    distance = 2.0 * framed + 1.0
    origin = [distance * c for c in towards]
    to_world = mi.ScalarTransform4f().look_at(
        origin=origin, target=[0, 0, 0], up=[0, 0, 1]
    ) @ mi.ScalarTransform4f().scale([framed, framed, 1.0])
    light = spherical(*args.light)
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
            "sensor": {
                "type": "orthographic",
                "to_world": to_world,
                "near_clip": 0.01,
                "far_clip": 2.0 * distance,
                "sampler": {"type": "independent", "sample_count": args.spp},
                "film": {
                    "type": "hdrfilm",
                    "width": args.size,
                    "height": args.size,
                    "pixel_format": "rgba",
                    "component_format": "float32",
                    "rfilter": {"type": "box"},
                },
            },
            "sun": {
                "type": "directional",
                "direction": [-c for c in light],
                "irradiance": {"type": "rgb", "value": [math.pi] * 3},
            },
            "sphere": {
                "type": "sphere",
                "radius": 1.0,
                "bsdf": {"type": "measured", "filename": args.bsdf},
            },
        }
    )
    mi.render(scene, seed=args.seed, spp=args.spp)
    scene.sensors()[0].film().bitmap(raw=False).write(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
