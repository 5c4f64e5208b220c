"""The deepbrdf module's contract: shapes and NaN cells, round trips, batch forms equal to single
calls, errors as Python exceptions naming the file, the GIL released and Ctrl-C honoured."""
import os
import threading
import time
import _thread
import signal

import numpy as np
import pytest

import deepbrdf


def test_tables_have_the_merl_shape_and_nan_invalid_cells(chrome, tmp_path):
    assert chrome.shape == (3, 90, 90, 180) and chrome.dtype == np.float32
    invalid = np.isnan(chrome)
    # A cell is invalid in all three channels, and the grid has below-horizon cells.
    assert (invalid[0] == invalid[1]).all() and (invalid[0] == invalid[2]).all()
    assert 0 < invalid[0].sum() < invalid[0].size
    assert (chrome[~invalid] >= 0).all()
    deepbrdf.write_merl(tmp_path / "c.binary", chrome)
    again = deepbrdf.read_merl(tmp_path / "c.binary")
    np.testing.assert_array_equal(again, chrome)
    # float64 and negative invalid values are accepted and written alike.
    as_f64 = np.where(np.isnan(chrome), -1.0, chrome.astype(np.float64))
    deepbrdf.write_merl(tmp_path / "d.binary", as_f64)
    assert (tmp_path / "d.binary").read_bytes() == (tmp_path / "c.binary").read_bytes()


def test_bundled_names():
    names = deepbrdf.bundled_names()
    assert len(names) == 166 and "merl/chrome" in names and "rgl-measured/paper_white_rgb" in names
    assert len(deepbrdf.bundled_names("merl")) == 100
    with pytest.raises(ValueError):
        deepbrdf.bundled_names("nope")
    with pytest.raises(ValueError, match="chrome"):
        deepbrdf.bundled("chrom")


def test_model_round_trip_and_batches(model, chrome):
    assert model.k == 10 and len(model.id) == 32
    latent = model.encode(chrome)
    assert latent.shape == (model.k,) and latent.dtype == np.float32
    table = model.decode(latent)
    assert table.shape == (3, 90, 90, 180)
    np.testing.assert_array_equal(np.isnan(table), np.isnan(chrome))
    assert deepbrdf.relae(chrome, table) < 0.5
    red = deepbrdf.bundled("red-plastic")
    stack = np.stack([chrome, red])
    latents = model.encode_batch(stack)
    np.testing.assert_array_equal(latents[0], latent)
    np.testing.assert_array_equal(latents[1], model.encode(red))
    decoded = model.decode_batch(latents)
    assert decoded.shape == (2, 3, 90, 90, 180)
    np.testing.assert_array_equal(decoded[0], table)
    np.testing.assert_array_equal(model.reconstruct_batch(stack[:1])[0], table)
    path = model.interpolate(chrome, red, steps=3)
    assert path.shape == (3, 3, 90, 90, 180)
    np.testing.assert_array_equal(path[0], table)
    np.testing.assert_array_equal(path[2], decoded[1])


def test_edit_changes_the_attribute_asked_for(model, chrome):
    plastic = deepbrdf.bundled("red-plastic")
    before = deepbrdf.attributes(plastic)
    assert before.shape == (7,)
    after = deepbrdf.attributes(model.edit(plastic, roughness_scale=2.0, mode="analytic"))
    # Re-estimated on the edited table, the roughness has grown (how much the other attributes
    # move with it is the editing suite's measure, docs/editing.md).
    assert after[6] > 1.5 * before[6], (before, after)
    stretched = deepbrdf.attributes(model.edit(plastic, roughness_scale=2.0, mode="stretch"))
    assert stretched[6] > 1.5 * before[6], (before, stretched)
    by_parts = deepbrdf.attributes(model.edit(plastic, roughness_scale=2.0))
    assert by_parts[6] > 1.5 * before[6], (before, by_parts)
    with pytest.raises(ValueError, match="not both"):
        model.edit(chrome, roughness=0.1, roughness_scale=2)
    with pytest.raises(ValueError, match="edit mode"):
        model.edit(chrome, roughness=0.1, mode="sideways")
    # An albedo the fit finds none of cannot be scaled: said, not silently ignored.
    with pytest.warns(UserWarning, match="no diffuse albedo"):
        model.edit(deepbrdf.bundled("gold-metallic-paint"), diffuse_scale=0.5)


def test_render_recover_and_relae(model, chrome, tmp_path):
    image = deepbrdf.render(chrome, size=64, spp=16, alpha=True)
    assert image.shape == (64, 64, 4) and image.dtype == np.float32
    assert image[..., 3].max() == 1.0 and image[..., 3].min() == 0.0
    assert deepbrdf.relae(image, image) == 0.0
    deepbrdf.write_exr(tmp_path / "photo.exr", image)
    from_file = model.recover(tmp_path / "photo.exr")
    from_array = model.recover(image)
    np.testing.assert_array_equal(from_file, from_array)
    assert from_array.shape == (3, 90, 90, 180)
    # An 8-bit sRGB photo (as a camera gives) works too.
    srgb = (np.clip(image[..., :3], 0, 1) ** (1 / 2.2) * 255 + 0.5).astype(np.uint8)
    assert model.recover(srgb).shape == (3, 90, 90, 180)
    with pytest.raises(ValueError, match="uint8"):
        model.recover(srgb[..., :2])
    with pytest.raises(ValueError):
        model.recover(np.zeros((64, 64, 3), dtype=np.float32))


def test_bad_arrays_are_value_errors(model, chrome):
    for bad in [np.zeros((3, 90, 90)), np.zeros((3, 90, 90, 179)), "text", None]:
        with pytest.raises(ValueError):
            model.encode(bad)
    infinite = chrome.copy()
    infinite[0, 0, 0, 0] = np.inf
    with pytest.raises(ValueError, match="not finite"):
        model.encode(infinite)
    with pytest.raises(ValueError, match="k = 10"):
        model.decode(np.zeros(3))
    with pytest.raises(ValueError):
        model.decode(np.full(10, np.nan))
    with pytest.raises(ValueError):
        deepbrdf.render(chrome, shape="teapot")
    with pytest.raises(ValueError):
        deepbrdf.render(chrome, size=0)
    with pytest.raises(ValueError):
        deepbrdf.write_png("x.png", np.zeros((4, 4)))
    with pytest.raises(ValueError):
        deepbrdf.write_bsdf("x.bsdf", chrome, rgb=0)
    with pytest.raises(ValueError):
        deepbrdf.write_bsdf("x.bsdf", np.zeros((3, 90, 90)))


def test_bad_files_are_os_errors_naming_the_file(tmp_path):
    missing = tmp_path / "missing.binary"
    with pytest.raises(FileNotFoundError) as err:
        deepbrdf.read_merl(missing)
    assert err.value.filename == str(missing)
    short = tmp_path / "short.binary"
    short.write_bytes(b"\x5a\x00\x00\x00" * 3 + b"\x00" * 100)
    with pytest.raises(deepbrdf.FileFormatError, match="short.binary"):
        deepbrdf.read_merl(short)
    assert issubclass(deepbrdf.FileFormatError, OSError)
    with pytest.raises(OSError, match="garbage.bsdf"):
        (tmp_path / "garbage.bsdf").write_bytes(b"not a tensor file")
        deepbrdf.read_bsdf(tmp_path / "garbage.bsdf")
    with pytest.raises(OSError):
        deepbrdf.Model.load(tmp_path / "no-model")
    with pytest.raises(OSError):
        deepbrdf.write_merl(tmp_path / "no-dir" / "x.binary", deepbrdf.bundled("chrome"))
    with pytest.raises(OSError):
        deepbrdf.write_bsdf(tmp_path / "no-dir" / "x.bsdf", deepbrdf.bundled("chrome"))


def test_long_calls_release_the_gil(model, chrome):
    latent = model.encode(chrome)
    latents = np.stack([latent] * 4)
    done = threading.Event()
    ticks = 0

    def work():
        model.decode_batch(latents)
        done.set()

    thread = threading.Thread(target=work)
    thread.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    thread.join()
    # With the GIL held through the decodes this loop could not have run meanwhile.
    assert ticks > 20, ticks


def test_ctrl_c_stops_a_batch(model, chrome):
    latents = np.stack([model.encode(chrome)] * 200)
    # A process started with SIGINT ignored (a background job of a shell) has no KeyboardInterrupt
    # handler, and interrupt_main() then does nothing: install Python's own for this test.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        start = time.perf_counter()
        threading.Timer(0.3, _thread.interrupt_main).start()
        with pytest.raises(KeyboardInterrupt):
            model.decode_batch(latents)
        # 200 decodes take several seconds; the interrupt stops the batch at the next table.
        assert time.perf_counter() - start < 3.0
    finally:
        signal.signal(signal.SIGINT, previous)


def test_the_example_runs(tmp_path):
    from conftest import REPO
    import runpy
    import sys

    out = tmp_path / "side-by-side.png"
    sys.argv = ["roughness.py", str(out), "--size", "64", "--spp", "4"]
    runpy.run_path(str(REPO / "python/examples/roughness.py"), run_name="__main__")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
