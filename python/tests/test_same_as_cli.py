"""Python and the `experiments` command line give the same files, byte for byte: decode, encode
+ decode, edit (network and analytic), render (PNG and EXR), an RGL conversion."""
import json
import subprocess

import numpy as np

import deepbrdf


def run(experiments, *args):
    done = subprocess.run([str(experiments), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, f"experiments {' '.join(map(str, args))}: {done.stderr}"
    return done.stdout


def same_bytes(a, b):
    da, db = a.read_bytes(), b.read_bytes()
    assert len(da) == len(db), f"{a}: {len(da)} bytes, {b}: {len(db)}"
    assert da == db, f"{a} and {b} differ"


def test_encode_and_decode_equal_the_command_line(experiments, model, chrome, tmp_path):
    run(experiments, "encode", "chrome", "-o", tmp_path / "z.json")
    run(experiments, "decode", tmp_path / "z.json", "-o", tmp_path / "cli.binary")
    saved = json.loads((tmp_path / "z.json").read_text())
    assert saved["model_id"] == model.id
    latent = np.array(saved["latent"], dtype=np.float32)
    np.testing.assert_array_equal(model.encode(chrome), latent)
    deepbrdf.write_merl(tmp_path / "py.binary", model.decode(latent))
    same_bytes(tmp_path / "cli.binary", tmp_path / "py.binary")


def test_reconstruct_equals_the_command_line(experiments, model, chrome, tmp_path):
    run(experiments, "reconstruct", "chrome", "-o", tmp_path / "cli.binary")
    deepbrdf.write_merl(tmp_path / "py.binary", model.reconstruct(chrome))
    same_bytes(tmp_path / "cli.binary", tmp_path / "py.binary")


def test_edit_equals_the_command_line(experiments, model, chrome, tmp_path):
    run(experiments, "edit", "chrome", "--roughness-scale", "2", "-o", tmp_path / "cli.binary")
    deepbrdf.write_merl(tmp_path / "py.binary", model.edit(chrome, roughness_scale=2))
    same_bytes(tmp_path / "cli.binary", tmp_path / "py.binary")
    run(experiments, "edit", "chrome", "--roughness-scale", "2", "--mode", "residual",
        "-o", tmp_path / "cli-residual.binary")
    deepbrdf.write_merl(tmp_path / "py-residual.binary",
                        model.edit(chrome, roughness_scale=2, mode="residual"))
    same_bytes(tmp_path / "cli-residual.binary", tmp_path / "py-residual.binary")
    run(experiments, "edit", "chrome", "--mode", "analytic", "--diffuse", "0.5,0.25,0.03",
        "-o", tmp_path / "cli-analytic.binary")
    edited = model.edit(chrome, mode="analytic", diffuse=(0.5, 0.25, 0.03))
    deepbrdf.write_merl(tmp_path / "py-analytic.binary", edited)
    same_bytes(tmp_path / "cli-analytic.binary", tmp_path / "py-analytic.binary")


def test_render_equals_the_command_line(experiments, model, chrome, tmp_path):
    run(experiments, "edit", "chrome", "--roughness", "0.2", "-o", tmp_path / "edited.binary")
    for material, table in [("chrome", chrome), (tmp_path / "edited.binary", None)]:
        if table is None:
            table = deepbrdf.read_merl(material)
        run(experiments, "render", material, "-o", tmp_path / "cli.png", "--exr", tmp_path / "cli.exr",
            "--size", "48", "--spp", "4", "--light", "sun:30,60", "--shape", "torus")
        image = deepbrdf.render(table, size=48, spp=4, light="sun:30,60", shape="torus", alpha=True)
        assert image.shape == (48, 48, 4)
        deepbrdf.write_png(tmp_path / "py.png", image)
        deepbrdf.write_exr(tmp_path / "py.exr", image)
        same_bytes(tmp_path / "cli.png", tmp_path / "py.png")
        same_bytes(tmp_path / "cli.exr", tmp_path / "py.exr")
        # The (H, W, 3) form is the same radiance.
        rgb = deepbrdf.render(table, size=48, spp=4, light="sun:30,60", shape="torus")
        np.testing.assert_array_equal(rgb, image[..., :3])


def test_read_bsdf_equals_convert(experiments, tmp_path):
    # A tensor file written by the binary (the bundled real measurements are stored as zstd
    # frames, which the reader of a user's file does not take).
    bsdf = tmp_path / "red-plastic.bsdf"
    run(experiments, "export-bsdf", "red-plastic", "-o", bsdf)
    run(experiments, "convert", bsdf, "-o", tmp_path / "cli.binary")
    deepbrdf.write_merl(tmp_path / "py.binary", deepbrdf.read_bsdf(bsdf))
    same_bytes(tmp_path / "cli.binary", tmp_path / "py.binary")
    np.testing.assert_array_equal(
        deepbrdf.read_merl(tmp_path / "cli.binary"), deepbrdf.read_bsdf(bsdf)
    )


def test_write_bsdf_equals_export_bsdf(experiments, chrome, tmp_path):
    run(experiments, "export-bsdf", "chrome", "-o", tmp_path / "cli.bsdf")
    deepbrdf.write_bsdf(tmp_path / "py.bsdf", chrome, description="chrome")
    same_bytes(tmp_path / "cli.bsdf", tmp_path / "py.bsdf")
    run(experiments, "export-bsdf", "chrome", "--theta-i", "4", "--rgb", "16",
        "-o", tmp_path / "cli-small.bsdf")
    deepbrdf.write_bsdf(tmp_path / "py-small.bsdf", chrome, description="chrome", theta_i=4,
                        rgb=16)
    same_bytes(tmp_path / "cli-small.bsdf", tmp_path / "py-small.bsdf")
    # What it writes reads back as a table close to the one written.
    back = deepbrdf.read_bsdf(tmp_path / "py.bsdf")
    assert back.shape == chrome.shape
