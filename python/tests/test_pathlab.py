"""Tests of the Python module (run by ctest with pytest: ctest -R Python).

The module must give the command line's bytes for the same settings, compare's statistics
under the same names, a KeyboardInterrupt within a pass after Ctrl-C, and TypeErrors that name
the valid values.
"""
import json
import os
import signal
import struct
import subprocess
import sys
import threading
import time
import zlib

import numpy as np
import pytest

import pathlab

BINARY = os.environ["PATHLAB_BINARY"]
SOURCE = os.environ["PATHLAB_SOURCE_DIR"]


def cli(*args):
    r = subprocess.run([BINARY, *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout


def same_bits(a, b):
    return a.shape == b.shape and a.dtype == b.dtype and np.array_equal(a.view(np.uint32), b.view(np.uint32))


def read_exr_channels(path):
    """Every channel of a scanline EXR as pathlab writes them (float, uncompressed or ZIP), by name
    ("R", "stderr.R"): NumPy has no EXR reader, and pathlab.read returns the RGB image only."""
    data = open(path, "rb").read()
    assert data[:4] == b"\x76\x2f\x31\x01", path
    pos, attributes = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        size = struct.unpack_from("<i", data, type_end + 1)[0]
        attributes[data[pos:name_end].decode()] = data[type_end + 5:type_end + 5 + size]
        pos = type_end + 5 + size
    pos += 1
    names, listing, p = [], attributes["channels"], 0
    while listing[p] != 0:  # name, pixel type (2: float), pLinear, reserved, x and y sampling
        end = listing.index(b"\0", p)
        assert struct.unpack_from("<i", listing, end + 1)[0] == 2, "not a float channel"
        names.append(listing[p:end].decode())
        p = end + 17
    x0, y0, x1, y1 = struct.unpack("<4i", attributes["dataWindow"])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    compression = attributes["compression"][0]
    lines = {0: 1, 2: 1, 3: 16}[compression]  # none, ZIPS, ZIP
    chunks = (height + lines - 1) // lines
    out = {name: np.zeros((height, width), np.float32) for name in names}
    for offset in struct.unpack_from(f"<{chunks}Q", data, pos):
        y, size = struct.unpack_from("<ii", data, offset)
        n = min(lines, y1 + 1 - y)
        raw = data[offset + 8:offset + 8 + size]
        if compression and size < n * width * 4 * len(names):
            t = np.frombuffer(zlib.decompress(raw), np.uint8).astype(np.int64)
            t[1:] -= 128
            t = (np.cumsum(t) % 256).astype(np.uint8)  # the predictor undone
            half = (len(t) + 1) // 2
            raw = np.empty_like(t)
            raw[0::2], raw[1::2] = t[:half], t[half:]  # the two halves interleaved again
            raw = raw.tobytes()
        rows = np.frombuffer(raw, "<f4").reshape(n, len(names), width)
        for c, name in enumerate(names):
            out[name][y - y0:y - y0 + n] = rows[:, c]
    return out


def read_render(path):
    """(mean, standard_error) of a render's EXR, as (height, width, 3) float32 arrays."""
    ch = read_exr_channels(path)
    return (np.stack([ch["R"], ch["G"], ch["B"]], axis=-1), np.stack([ch["stderr.R"], ch["stderr.G"], ch["stderr.B"]], axis=-1))


def same_render(a, b):
    """The CLI tests' criterion (tests/test_distributed.cpp): the means and the standard errors bit for bit."""
    return same_bits(a[0], b[0]) and same_bits(a[1], b[1])


def checkpoint_header(path):
    """A checkpoint's header lines (job/checkpoint.hpp) as a dict: passes, command, ..."""
    data = open(path, "rb").read()
    assert data[:8] == b"PLCKPT\r\n"
    size = struct.unpack_from("<I", data, 12)[0]
    return dict(line.split("=", 1) for line in data[16:16 + size].decode().splitlines())


def test_import_without_numpy_says_which_python_lacks_it():
    # sys.modules['numpy'] = None makes `import numpy` fail, as in a Python without NumPy.
    code = "import sys; sys.modules['numpy'] = None; import pathlab"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode != 0
    assert "ImportError: pathlab needs NumPy, which this Python (" + sys.executable in r.stderr, r.stderr
    assert "-m pip install numpy" in r.stderr, r.stderr


def test_lists_the_scenes_and_the_estimators():
    assert pathlab.scenes()[3] == "ceiling-glossy"
    assert len(pathlab.scenes()) == 8
    assert {"pt-mis", "direct-mis", "bdpt", "vcm"} <= set(pathlab.algorithms())


def test_load_takes_indices_names_and_files_with_defines():
    assert pathlab.load(3).name == "ceiling-glossy"
    assert pathlab.load("ceiling-glossy").index == 3
    scene = pathlab.load(os.path.join(SOURCE, "scenes/example.xml"), defines={"spp": "8"})
    assert scene.index is None and scene.name == "example"
    assert scene.parameters == {"spp": "8"}
    assert scene.resolution == (320, 240)
    with pytest.raises(ValueError, match="no scene uses \\$sp"):
        pathlab.load(os.path.join(SOURCE, "scenes/example.xml"), defines={"sp": "8"})


@pytest.mark.parametrize("scene,algorithm,extra", [
    ("3", "pt-mis", []),
    ("4", "bdpt", []),  # splats: the light-tracing strategy
    ("scenes/example.xml", "direct-mis", ["-D", "spp=2"]),
    ("3", "pt-mis", ["--spectral", "--rr-depth", "1"]),
    ("scenes/many-lights.xml", "direct-mis", ["--light-sampler", "ris", "--ris-candidates", "3"]),
    # The estimators' own options, by their command-line names.
    ("3", "sppm", ["--photons", "300", "--radius", "0.05", "--alpha", "0.5"]),
    ("3", "vcm", ["--no-merging", "--mis", "power"]),
    ("3", "ic", ["--ic-rays", "16", "--ic-error", "0.5", "--ic-no-gradients"]),
    ("3", "pbgi", ["--pbgi-surfels", "400", "--pbgi-bounces", "1", "--pbgi-cutoff", "0.1"]),
    ("scenes/fog-box.xml", "pm", ["--volume-estimate", "points", "--photons", "200"]),
    ("3", "ppg", ["--guiding-spp", "3", "--guiding-rr", "--guiding-fraction", "learned"]),
    ("scenes/fog-box.xml", "ppg", ["--guiding-spp", "3", "--guiding", "vmm"]),  # guided in media, by mixtures
    ("scenes/gltf/room.glb", "pt-mis", []),  # a glTF scene
])
def test_render_equals_the_command_line_bit_for_bit(tmp_path, scene, algorithm, extra):
    path = os.path.join(SOURCE, scene) if scene.endswith((".xml", ".glb")) else scene
    out = tmp_path / "cli.exr"
    cli(path, "-a", algorithm, "--spp", 3, "--seed", 77, "--resolution", "20x14", "-q", "-o", out, *extra)
    defines = dict([extra[1].split("=")]) if extra[:1] == ["-D"] else {}
    # The same options by keyword: --light-sampler ris -> light_sampler="ris", --spectral -> spectral=True.
    options = {}
    for i, word in enumerate(extra):
        if word.startswith("--"):
            value = extra[i + 1] if i + 1 < len(extra) and not extra[i + 1].startswith("-") else True
            if isinstance(value, str) and value.isdigit():
                value = int(value)
            elif isinstance(value, str) and value.replace(".", "", 1).isdigit():
                value = float(value)
            options[word[2:].replace("-", "_")] = value
    img, stderr = pathlab.render(pathlab.load(path, defines=defines), algorithm=algorithm, spp=3, seed=77, resolution=(20, 14), **options)
    assert img.dtype == np.float32 and img.shape == (14, 20, 3) and stderr.shape == (14, 20, 3)
    assert same_bits(img, pathlab.read(str(out)))
    # Any thread count, and a scene reused for a second render, give the same bytes.
    again, _ = pathlab.render(pathlab.load(path, defines=defines), algorithm=algorithm, spp=3, seed=77, resolution=(20, 14), threads=1,
                              **options)
    assert same_bits(img, again)


def test_aovs_as_arrays_equal_the_command_lines_layers(tmp_path):
    out = tmp_path / "aovs.exr"
    cli("3", "--spp", 3, "--seed", 77, "--resolution", "20x14", "-q", "-o", out, "--aovs", "albedo,depth,variance,sample-count")
    img, stderr, aovs = pathlab.render(3, "pt-mis", spp=3, seed=77, resolution=(20, 14), aovs=["albedo", "depth", "variance", "sample-count"])
    layers = read_exr_channels(str(out))
    assert sorted(aovs) == ["albedo", "depth", "sample-count", "variance"]
    assert aovs["albedo"].shape == (14, 20, 3) and aovs["depth"].shape == (14, 20)
    assert same_bits(aovs["albedo"], np.stack([layers["Albedo.R"], layers["Albedo.G"], layers["Albedo.B"]], axis=-1))
    assert same_bits(aovs["depth"], layers["Z"])
    assert same_bits(aovs["variance"], np.stack([layers["Variance.R"], layers["Variance.G"], layers["Variance.B"]], axis=-1))
    assert (aovs["sample-count"] == 3).all()
    assert same_bits(img, pathlab.render(3, "pt-mis", spp=3, seed=77, resolution=(20, 14))[0])  # the image is the same with them
    with pytest.raises(ValueError, match="lt has no camera samples"):
        pathlab.render(3, "lt", spp=1, resolution=(4, 4), aovs="albedo")
    with pytest.raises(ValueError, match="unknown AOV 'shadow'"):
        pathlab.render(3, "pt-mis", spp=1, resolution=(4, 4), aovs="shadow")


def test_estimator_options_are_refused_as_on_the_command_line():
    with pytest.raises(ValueError, match="--photons sets the light paths of sppm, ppm and pm; pt-mis has no such count"):
        pathlab.render(3, "pt-mis", spp=1, resolution=(4, 4), photons=100)
    with pytest.raises(ValueError, match="--ic-rays must be 4 to 65536, got 2"):
        pathlab.render(3, "ic", spp=1, resolution=(4, 4), ic_rays=2)
    with pytest.raises(ValueError, match="leave vcm no strategy"):
        pathlab.render(3, "vcm", spp=1, resolution=(4, 4), no_merging=True, no_connections=True)
    with pytest.raises(TypeError, match="unexpected keyword argument 'photon'; the estimators' options: mis, photons"):
        pathlab.render(3, "sppm", spp=1, resolution=(4, 4), photon=100)
    with pytest.raises(ValueError, match="unknown mis 'heuristic'; valid: balance, power"):
        pathlab.render(3, "bdpt", spp=1, resolution=(4, 4), mis="heuristic")
    with pytest.raises(ValueError, match="--guiding-fraction must be a number in \\(0, 1\\] or 'learned', got '0'"):
        pathlab.render(3, "ppg", spp=1, resolution=(4, 4), guiding_fraction=0)
    with pytest.raises(ValueError, match="--guiding-fraction must be a number in \\(0, 1\\] or 'learned', got 'most'"):
        pathlab.render(3, "ppg", spp=1, resolution=(4, 4), guiding_fraction="most")
    with pytest.raises(ValueError, match="--guiding must be sd-tree or vmm, got 'gmm'"):
        pathlab.render(3, "ppg", spp=1, resolution=(4, 4), guiding="gmm")


def test_a_scene_files_own_settings_as_on_the_command_line(tmp_path):
    path = os.path.join(SOURCE, "scenes/example.xml")
    cli(path, "-D", "spp=2", "--resolution", "16x12", "-q", "-o", tmp_path / "a.pfm")
    img, _ = pathlab.render(pathlab.load(path, defines={"spp": "2"}), resolution=(16, 12))
    assert same_bits(img, pathlab.read(str(tmp_path / "a.pfm")))


def test_compare_gives_the_command_lines_statistics(tmp_path):
    a, _ = pathlab.render(2, spp=2, seed=1, resolution=(16, 16))
    b, _ = pathlab.render(2, spp=8, seed=2, resolution=(16, 16))
    pathlab.write(str(tmp_path / "a.exr"), a)
    pathlab.write(str(tmp_path / "b.exr"), b)
    expected = json.loads(cli("compare", tmp_path / "a.exr", tmp_path / "b.exr", "--json"))
    for key in ("a", "b"):
        del expected[key]
    assert pathlab.compare(a, b) == expected
    assert pathlab.compare(str(tmp_path / "a.exr"), b) == expected
    assert pathlab.compare(a, a)["all"]["rmse"] == 0
    # Nothing to compare (every pixel NaN): no statistic (NaN), not a perfect 0.
    nan = np.full_like(a, np.nan)
    stats = pathlab.compare(nan, b)
    assert stats["compared"] == 0 and np.isnan(stats["all"]["rmse"])
    assert np.isnan(pathlab.rmse(nan, b))
    # reference_se of another shape than the reference is refused, not ignored.
    with pytest.raises(ValueError, match="reference_se is 8x8 but the reference 16x16"):
        pathlab.rmse(a, b, np.zeros((8, 8, 3), dtype=np.float32))
    # A sample count past the last sample index is refused at once (it never returned).
    with pytest.raises(ValueError, match=r"spp must be an int from 1 to 4611686018427387903 \(sample indices end at 2\^62\), not 9223372036854775808"):
        pathlab.render(2, spp=2**63, resolution=(4, 4))
    # An int out of range is a ValueError naming the argument (pybind11 called it a wrong type);
    # another type a TypeError.
    for name, value in [("spp", -1), ("spp", 2**64), ("spp", 0), ("seed", -1), ("seed", 2**64), ("threads", -1),
                        ("max_depth", -2), ("rr_depth", -1), ("ris_candidates", 0)]:
        with pytest.raises(ValueError, match=f"{name} must be an int from .* not {value}"):
            pathlab.render(2, resolution=(4, 4), **{name: value})
    for name, value in [("spp", 1.5), ("spp", True), ("seed", "7"), ("threads", 2.0)]:
        with pytest.raises(TypeError, match=f"{name} must be an int, not"):
            pathlab.render(2, resolution=(4, 4), **{name: value})


def test_write_and_read_round_trip(tmp_path):
    rng = np.random.default_rng(5)
    img = rng.random((7, 9, 3), dtype=np.float32) * 4
    for ext in ("exr", "pfm"):
        pathlab.write(str(tmp_path / f"x.{ext}"), img)
        assert same_bits(pathlab.read(str(tmp_path / f"x.{ext}")), img)
    pathlab.write(str(tmp_path / "x.png"), img.astype(np.float64), exposure=-1)  # float64 converted
    assert (tmp_path / "x.png").stat().st_size > 0
    with pytest.raises(ValueError, match="shape"):
        pathlab.write(str(tmp_path / "y.exr"), np.zeros((4, 4)))
    with pytest.raises(ValueError, match=".exr, .hdr, .pfm, .png"):
        pathlab.write(str(tmp_path / "y.jpg"), img)


def test_ctrl_c_stops_the_render_with_keyboard_interrupt_within_a_pass():
    scene = pathlab.load(3)
    pathlab.render(scene, spp=1, resolution=(64, 64))  # build the scene first
    sent = []

    def interrupt():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(0.5, interrupt)
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):  # (a render that ignored Ctrl-C would end after its 20 s)
        pathlab.render(scene, time=20, resolution=(64, 64))
    stopped = time.monotonic()
    timer.join()
    assert sent, "the signal was not sent"
    # A pass of 64x64 takes milliseconds; the render stops after its current batch of them.
    assert stopped - sent[0] < 2.0, f"stopped {stopped - sent[0]:.2f} s after Ctrl-C"
    assert stopped - start < 10


def test_the_gil_is_released_while_rendering():
    ticks = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks[0] += 1
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    pathlab.render(2, time=0.5, resolution=(32, 32))
    stop.set()
    t.join()
    assert ticks[0] > 50, "the other thread did not run while rendering"


def test_wrong_types_raise_type_error_naming_the_valid_values():
    with pytest.raises(TypeError, match="pt-mis"):
        pathlab.render(3, algorithm=4)
    with pytest.raises(TypeError, match="ceiling-glossy"):
        pathlab.render([3])
    with pytest.raises(TypeError, match="ceiling-glossy"):
        pathlab.load(3.5)
    with pytest.raises(TypeError, match="spp"):  # pybind11 lists the signature: names and types
        pathlab.render(3, spp="many")
    with pytest.raises(TypeError, match="independent, sobol"):
        pathlab.render(3, sampler=1)
    with pytest.raises(TypeError, match="shape"):
        pathlab.compare({"a": 1}, np.zeros((2, 2, 3)))
    with pytest.raises(ValueError, match="(?s)unknown algorithm 'pt-magic'.*pt-mis"):
        pathlab.render(3, algorithm="pt-magic", spp=1)
    with pytest.raises(ValueError, match="(?s)unknown scene 'kitchen'.*ceiling-glossy"):
        pathlab.load("kitchen")


def test_rmse_refuses_standard_errors_that_are_not_standard_errors():
    img = np.full((4, 4, 3), 0.5, np.float32)
    ref = np.full((4, 4, 3), 0.4, np.float32)
    assert pathlab.rmse(img, ref) == pytest.approx(0.1, rel=1e-5)
    for bad in (np.nan, -1.0, np.inf):
        se = np.zeros((4, 4, 3), np.float32)
        se[2, 1, 0] = bad
        with pytest.raises(ValueError, match=r"standard error at pixel \(1, 2\)"):
            pathlab.rmse(img, ref, reference_se=se)


def test_params_update_and_their_errors():
    scene = pathlab.load(2)
    params = pathlab.params(scene)
    red = params["red.reflectance.value"]
    assert red.dtype == np.float32 and red.shape == (3,)
    assert np.allclose(red, [0.803922, 0.152941, 0.152941])
    darker = pathlab.update(scene, {"red.reflectance.value": [0.5, 0.1, 0.1]})
    assert np.allclose(pathlab.params(darker)["red.reflectance.value"], [0.5, 0.1, 0.1])
    assert np.array_equal(pathlab.params(scene)["red.reflectance.value"], red)  # a copy: the original is unchanged
    assert darker.hash == "" and darker.name == scene.name
    assert np.allclose(pathlab.params(pathlab.update(scene, {"red.reflectance.value": 0.25}))["red.reflectance.value"], 0.25)
    # The updated scene renders as the command line renders the scene file with that value.
    a, _ = pathlab.render(darker, "pt-mis", spp=2, seed=3, resolution=(8, 8))
    b, _ = pathlab.render(scene, "pt-mis", spp=2, seed=3, resolution=(8, 8))
    assert a.mean() < b.mean()
    with pytest.raises(ValueError, match=r"red.reflectance.value: 1.5 is outside its range \[0, 1\]"):
        pathlab.update(scene, {"red.reflectance.value": 1.5})
    with pytest.raises(ValueError, match="red.reflectance.value takes 3 values"):
        pathlab.update(scene, {"red.reflectance.value": [0.1, 0.2]})
    with pytest.raises(ValueError, match="(?s)unknown parameter 'rd.reflectance.value'.*red.reflectance.value"):
        pathlab.update(scene, {"rd.reflectance.value": 0.5})
    with pytest.raises(TypeError, match="must be a number"):
        pathlab.update(scene, {"red.reflectance.value": "red"})


def test_gradient_and_optimize_give_the_command_lines_numbers(tmp_path):
    # pathlab gradient: the mean pixel value's adjoint, the replay with seed + 1.
    out = cli("gradient", "--scene", "2", "--params", "red.reflectance.value,light.emitter.radiance.value", "--spp", "2",
              "--seed", "5", "--resolution", "12x10", "--out", tmp_path / "g")
    adjoint = np.full((10, 12, 3), 1.0 / (3 * 12 * 10), dtype=np.float32)
    g = pathlab.gradient(2, ["red.reflectance.value", "light.emitter.radiance.value"], adjoint, spp=2, seed=6)
    for name in g:
        line = next(l for l in out.splitlines() if l.startswith(name + ": dLoss/dtheta = ["))
        printed = [float(x) for x in line.split("[")[1].split("]")[0].split(",")]
        assert np.allclose(g[name], printed, rtol=1e-5, atol=0), (name, g[name], printed)
    assert g["red.reflectance.value"][0] > 0 and g["light.emitter.radiance.value"].shape == (3,)
    # pathlab.loss: the L2 loss's value and adjoint.
    img, target = np.full((2, 2, 3), 0.5, np.float32), np.zeros((2, 2, 3), np.float32)
    value, adj = pathlab.loss(img, target)
    assert value == pytest.approx(0.25) and np.allclose(adj, 2 * 0.5 / 12)
    # pathlab optimize: the same loop, the same parameters after the last step.
    truth = pathlab.update(2, {"red.reflectance.value": [0.3, 0.6, 0.2]})
    target, _ = pathlab.render(truth, "pt-mis", spp=16, seed=9, resolution=(12, 10))
    pathlab.write(str(tmp_path / "target.exr"), target)
    cli("optimize", "--scene", "2", "--params", "red.reflectance.value", "--target", tmp_path / "target.exr", "--iterations", "12",
        "--lr", "0.05", "--spp", "2", "--out", tmp_path / "o", "-q")
    expected = json.load(open(tmp_path / "o" / "params.json"))["params"]["red.reflectance.value"]
    r = pathlab.optimize(2, str(tmp_path / "target.exr"), "red.reflectance.value", iterations=12, lr=0.05, spp=2)
    assert np.allclose(r["params"]["red.reflectance.value"], expected, rtol=1e-5, atol=1e-7), (r["params"], expected)
    assert len(r["loss"]) == 12 and r["loss"][-1] < r["loss"][0]
    with pytest.raises(ValueError, match="(?s)unknown parameter 'red'"):
        pathlab.gradient(2, "red", adjoint)
    with pytest.raises(ValueError, match="iterations must be an int from 0"):
        pathlab.optimize(2, target, "red.reflectance.value", iterations=-1)


# ---- the command line's --first-sample, --checkpoint, --checkpoint-every and --resume -----------

SMALL = dict(seed=5, resolution=(16, 12))
SMALL_CLI = ["--seed", 5, "--resolution", "16x12", "-q"]


def test_the_exr_reader_of_these_tests_reads_what_pathlab_reads(tmp_path):
    cli("3", "--spp", 2, *SMALL_CLI, "-o", tmp_path / "a.exr")
    mean, se = read_render(str(tmp_path / "a.exr"))
    assert same_bits(mean, pathlab.read(str(tmp_path / "a.exr")))
    assert se.min() >= 0 and se.max() > 0


@pytest.mark.parametrize("algorithm", ["pt-mis", "bdpt"])
def test_first_sample_equals_the_command_line_bit_for_bit(tmp_path, algorithm):
    out = tmp_path / "cli.exr"
    cli("3", "-a", algorithm, "--spp", 3, "--first-sample", 5, "--seed", 77, "--resolution", "20x14", "-q", "-o", out)
    img, se = pathlab.render(3, algorithm, spp=3, seed=77, resolution=(20, 14), first_sample=5)
    assert same_render((img, se), read_render(str(out)))
    # Other samples than those of the first 3 passes.
    first, _ = pathlab.render(3, algorithm, spp=3, seed=77, resolution=(20, 14))
    assert not same_bits(img, first)


def test_renders_of_disjoint_ranges_merge_into_the_one_shot_render(tmp_path):
    # As the command line's MergeOfTwoHalvesEqualsTheOneShotRender: merged from checkpoints, the
    # one-shot render's mean and standard errors bit for bit.
    cli("3", "--spp", 10, *SMALL_CLI, "-o", tmp_path / "whole.exr")
    pathlab.render(3, spp=4, **SMALL, checkpoint=tmp_path / "a.ckpt")
    img, _ = pathlab.render(3, spp=6, first_sample=4, **SMALL, checkpoint=str(tmp_path / "b.ckpt"))
    assert checkpoint_header(tmp_path / "a.ckpt")["passes"] == "0-3"
    assert checkpoint_header(tmp_path / "b.ckpt")["passes"] == "4-9"
    cli("merge", tmp_path / "m.exr", tmp_path / "b.ckpt", tmp_path / "a.ckpt")
    assert same_render(read_render(str(tmp_path / "m.exr")), read_render(str(tmp_path / "whole.exr")))
    # The part alone is samples 4-9 of the same render, as the command line renders them.
    cli("3", "--spp", 6, "--first-sample", 4, *SMALL_CLI, "-o", tmp_path / "b.exr")
    assert same_bits(img, pathlab.read(str(tmp_path / "b.exr")))


@pytest.mark.parametrize("scene,algorithm,defines,options", [
    ("3", "pt-mis", {}, {}),
    ("scenes/example.xml", "sppm", {"spp": "2"}, {"photons": 300, "radius": 0.05, "spectral": True}),
])
def test_the_command_line_continues_a_python_checkpoint(tmp_path, scene, algorithm, defines, options):
    path = os.path.join(SOURCE, scene) if scene.endswith((".xml", ".glb")) else scene
    flags = [w for k, v in options.items() for w in (["--" + k] if v is True else ["--" + k, v])]
    cli(path, "-a", algorithm, *[w for k, v in defines.items() for w in ("-D", f"{k}={v}")], *flags, "--spp", 9, *SMALL_CLI,
        "-o", tmp_path / "whole.exr")
    ckpt = tmp_path / "c.ckpt"
    pathlab.render(pathlab.load(path, defines=defines), algorithm, spp=4, **SMALL, checkpoint=ckpt, checkpoint_every=0, **options)
    assert checkpoint_header(ckpt)["passes"] == "0-3"
    # `pathlab --resume FILE` alone: the checkpoint records the Python render as a command.
    cli("--resume", ckpt, "--spp", 9, "-q", "-o", tmp_path / "resumed.exr")
    assert same_render(read_render(str(tmp_path / "resumed.exr")), read_render(str(tmp_path / "whole.exr")))
    assert checkpoint_header(ckpt)["passes"] == "0-8"


def test_python_continues_a_command_line_checkpoint(tmp_path):
    cli("3", "--spp", 9, *SMALL_CLI, "-o", tmp_path / "whole.exr")
    ckpt = tmp_path / "c.ckpt"
    cli("3", "--spp", 4, *SMALL_CLI, "--checkpoint", ckpt, "-o", tmp_path / "part.exr")
    # Another render's checkpoint, or more passes than asked for: refused as on the command line.
    with pytest.raises(ValueError, match="seed: 5 in the checkpoint, 6 in this render"):
        pathlab.render(3, spp=9, seed=6, resolution=(16, 12), resume=ckpt)
    with pytest.raises(ValueError, match=r"holds passes 0-3, more than this render's 0-1 \(raise --spp to continue it\)"):
        pathlab.render(3, spp=2, **SMALL, resume=ckpt)
    # A checkpoint that exists is not replaced by a render that does not resume it.
    with pytest.raises(ValueError, match="c.ckpt exists: continue that render with --resume"):
        pathlab.render(3, spp=9, **SMALL, checkpoint=ckpt)
    assert checkpoint_header(ckpt)["passes"] == "0-3"
    # resume= continues it to the bytes of the render never interrupted, and goes on
    # checkpointing to it.
    resumed = pathlab.render(3, spp=9, **SMALL, resume=str(ckpt))
    assert same_render(resumed, read_render(str(tmp_path / "whole.exr")))
    assert checkpoint_header(ckpt)["passes"] == "0-8"


def test_first_sample_and_checkpoint_values_are_refused_as_on_the_command_line(tmp_path):
    for value in (-1, 2**64):
        with pytest.raises(ValueError, match=f"first_sample must be an int from 0 to 18446744073709551615, not {value}"):
            pathlab.render(2, spp=1, resolution=(4, 4), first_sample=value)
    # Sample indices end at 2^62: the command line's check and message.
    with pytest.raises(ValueError, match=r"--first-sample 4611686018427387903 with 2 samples per pixel reaches past the last sample index"):
        pathlab.render(2, spp=2, resolution=(4, 4), first_sample=2**62 - 1)
    with pytest.raises(ValueError, match="--first-sample .* with --time and no --spp may reach past the last sample index"):
        pathlab.render(2, time=1, resolution=(4, 4), first_sample=2**62 - 4)
    with pytest.raises(TypeError, match="first_sample must be an int, not float"):
        pathlab.render(2, spp=1, resolution=(4, 4), first_sample=1.5)
    for value in (-1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match=r"--checkpoint-every must be zero \(only at the end\) or a positive number of seconds"):
            pathlab.render(2, spp=1, resolution=(4, 4), checkpoint_every=value)
    missing = tmp_path / "missing.ckpt"
    with pytest.raises(ValueError, match=f"{missing}: cannot read the checkpoint"):
        pathlab.render(2, spp=1, resolution=(4, 4), resume=missing)
    (tmp_path / "not.ckpt").write_bytes(b"an image")
    with pytest.raises(ValueError, match="not.ckpt: not a pathlab checkpoint"):
        pathlab.render(2, spp=1, resolution=(4, 4), resume=tmp_path / "not.ckpt")
    with pytest.raises(TypeError, match="checkpoint must be a file name \\(str or path\\), not int"):
        pathlab.render(2, spp=1, resolution=(4, 4), checkpoint=3)
    with pytest.raises(TypeError, match="resume must be a file name"):
        pathlab.render(2, spp=1, resolution=(4, 4), resume=b"c.ckpt")
    # A file that exists (here the scene file) is not a checkpoint to write over.
    scene_file = os.path.join(SOURCE, "scenes/example.xml")
    with pytest.raises(ValueError, match="example.xml exists: continue that render with --resume"):
        pathlab.render(pathlab.load(scene_file), spp=1, resolution=(4, 4), checkpoint=scene_file)
    # A scene changed by update() hashes as the file's: its checkpoints would be taken for the file's.
    with pytest.raises(ValueError, match="checkpoint and resume take a scene as loaded"):
        pathlab.render(pathlab.update(2, {"red.reflectance.value": 0.5}), spp=1, resolution=(4, 4), checkpoint=tmp_path / "u.ckpt")
    assert not (tmp_path / "u.ckpt").exists()
