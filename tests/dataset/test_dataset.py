"""Tests of the Algorithm 1 data set generator and its CSV/NPZ files."""

from __future__ import annotations

import csv
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz import dataset as D
from eyeviz.core.geometry import EyePair, intervals_to_bitmap

SMALL = dict(eyes=EyePair(30.0, 10.0, 64), r_min=100.0, r_max=400.0, g_max=60.0)
EYEVIZ = [sys.executable, "-m", "eyeviz"]


@pytest.fixture(scope="module")
def paper_single():
    return D.generate(6000, seed=3)


@pytest.fixture(scope="module")
def paper_multi():
    return D.generate(6000, mode="multi", seed=3)


def _all_cases(paper_single, paper_multi):
    return [
        paper_single,
        paper_multi,
        D.generate(3000, mode="multi", seed=5, **SMALL),
        D.generate(1500, seed=6, unique_bitmaps=True, **SMALL),
    ]


# --- the elements --------------------------------------------------------------------


def test_bitmaps_equal_geometry_core(paper_single, paper_multi):
    for ds in _all_cases(paper_single, paper_multi):
        e, w = ds.eyes, ds.eyes.m // 2
        x, y = ds.r * np.cos(ds.phi), ds.r * np.sin(ds.phi)
        full_a, full_b = e.bitmaps(x, y, ds.g)
        assert ds.omega_a.dtype == bool and ds.omega_a.shape == (len(ds), w)
        np.testing.assert_array_equal(ds.omega_a, full_a[:, :w])
        np.testing.assert_array_equal(ds.omega_b, full_b[:, :w])
        # Property 3: nothing lit in the lower half, so Omega loses no information
        assert not full_a[:, w:].any() and not full_b[:, w:].any()
        la, ra, lb, rb = e.intervals(x, y, ds.g)
        np.testing.assert_array_equal(ds.omega_a, intervals_to_bitmap(la, ra, e.m, width=w))


def test_every_row_in_bfv_and_visible_to_both_eyes(paper_single, paper_multi):
    for ds in _all_cases(paper_single, paper_multi):
        e = ds.eyes
        assert e.in_bfv(ds.x, ds.y, ds.g).all()
        vis_a, vis_b = e.visible(ds.x, ds.y, ds.g)
        assert vis_a.all() and vis_b.all()
        assert (ds.omega_a.sum(1) >= 2).all() and (ds.omega_b.sum(1) >= 2).all()


def test_ranges(paper_single, paper_multi):
    for ds, p in [
        (paper_single, {}),
        (paper_multi, {}),
        (D.generate(3000, seed=1, **SMALL), SMALL),
    ]:
        e = p.get("eyes", D.PAPER_EYES)
        r_min, r_max, g_max = p.get("r_min", 1000.0), p.get("r_max", 5000.0), p.get("g_max", 500.0)
        assert (ds.r >= r_min).all() and (ds.r <= r_max).all()
        assert (ds.g >= ds.r * math.sin(e.gamma / 2)).all() and (ds.g <= g_max).all()
        assert (ds.g <= ds.r).all()
        a = np.arcsin(ds.g / ds.r)
        assert (ds.phi >= e.psi + a - 1e-12).all() and (ds.phi <= math.pi - e.psi - a + 1e-12).all()
        assert np.isfinite(ds.r).all() and np.isfinite(ds.phi).all()


def test_single_mode_spreads_over_whole_range(paper_single):
    # Algorithm 1 as written: r is uniform in [r_min, r_max], phi fills the BFV
    assert paper_single.r.min() < 1050 and paper_single.r.max() > 4950
    e = paper_single.eyes
    assert paper_single.phi.min() < e.psi + 0.1 and paper_single.phi.max() > math.pi - e.psi - 0.1


def test_multi_counts_follow_the_segment_plan():
    p = D.make_params(mode="multi", **SMALL)
    edges, counts = D.segment_plan(5000, p)
    assert counts.sum() == 5000 and len(edges) == len(counts) + 1
    assert np.allclose(np.diff(edges), 5.0)  # the paper's segment length
    mid = 0.5 * (edges[:-1] + edges[1:])
    assert np.abs(counts - 5000 * mid / mid.sum()).max() < 1  # largest remainders
    ds = D.generate(5000, mode="multi", seed=2, **SMALL)
    got = np.histogram(ds.r, bins=edges)[0]
    np.testing.assert_array_equal(got, counts)


def test_multi_segments_stop_where_step_9_rejects_everything():
    # g_max / sin(gamma/2) = 2000 / ... ; r beyond it can never be accepted
    e = D.PAPER_EYES
    r_cut = 20.0 / math.sin(e.gamma / 2)  # about 4584
    ds = D.generate(2000, mode="multi", seed=0, g_max=20.0)
    assert ds.r.max() <= r_cut and ds.r.max() > r_cut - 50


def _chi2(counts, expected):
    return float(((counts - expected) ** 2 / expected).sum())


def test_r_histogram_single_flat_multi_linear():
    n, bins = 40_000, 10
    edges = np.linspace(1000, 5000, bins + 1)
    mid = 0.5 * (edges[:-1] + edges[1:])
    flat = np.full(bins, n / bins)
    linear = n * mid / mid.sum()
    crit = 27.88  # chi-square, 9 degrees of freedom, p = 0.001
    single = np.histogram(D.generate(n, seed=11).r, bins=edges)[0]
    multi = np.histogram(D.generate(n, mode="multi", seed=11).r, bins=edges)[0]
    assert _chi2(single, flat) < crit
    assert _chi2(multi, linear) < crit
    assert _chi2(single, linear) > 20 * crit
    assert _chi2(multi, flat) > 20 * crit
    slope = np.polyfit(mid, multi, 1)[0]
    assert slope == pytest.approx(n / bins / mid.mean() * 1.0, rel=0.1)


def test_unique_bitmaps_are_unique_and_shift_distribution():
    ds = D.generate(1500, seed=4, unique_bitmaps=True, **SMALL)
    keys = np.concatenate([np.packbits(ds.omega_a, 1), np.packbits(ds.omega_b, 1)], 1)
    assert len(np.unique(keys, axis=0)) == len(ds)
    plain = D.generate(1500, seed=4, **SMALL)
    plain_keys = np.concatenate([np.packbits(plain.omega_a, 1), np.packbits(plain.omega_b, 1)], 1)
    assert len(np.unique(plain_keys, axis=0)) < len(plain)  # duplicates exist without it


def test_unique_bitmaps_exhausted_is_a_clear_error():
    with pytest.raises(EyevizError, match="distinct bitmap pairs"):
        D.generate(
            500, eyes=EyePair(30.0, 10.0, 8), r_min=100, r_max=200, g_max=60, unique_bitmaps=True
        )


def test_same_seed_same_elements_different_seed_different():
    a = D.generate(2000, seed=9, mode="multi")
    b = D.generate(2000, seed=9, mode="multi")
    c = D.generate(2000, seed=10, mode="multi")
    for k in ("omega_a", "omega_b", "r", "phi", "g"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert not np.array_equal(a.r, c.r)


# --- files ---------------------------------------------------------------------------


def _same_dataset(a, b, with_g=True):
    for k in ("omega_a", "omega_b", "r", "phi") + (("g",) if with_g else ()):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))


@pytest.mark.parametrize("suffix", ["csv", "npz"])
def test_same_seed_same_file_bytes(tmp_path, suffix):
    n = D.CHUNK + 123  # crosses a chunk boundary
    D.write(tmp_path / f"a.{suffix}", n, seed=7, mode="multi")
    D.write(tmp_path / f"b.{suffix}", n, seed=7, mode="multi")
    assert (tmp_path / f"a.{suffix}").read_bytes() == (tmp_path / f"b.{suffix}").read_bytes()
    back = D.load(tmp_path / f"a.{suffix}")
    assert len(back) == n
    _same_dataset(back, D.generate(n, seed=7, mode="multi"))
    if suffix == "csv":  # save() of the in-memory set writes the same bytes as write()
        D.save(back, tmp_path / "c.csv")
        assert (tmp_path / "c.csv").read_bytes() == (tmp_path / "a.csv").read_bytes()


def test_npz_round_trip_keeps_parameters(tmp_path):
    ds = D.generate(1000, seed=2, **SMALL)
    D.save(ds, tmp_path / "s.npz")
    back = D.load(tmp_path / "s.npz")
    _same_dataset(back, ds)
    assert back.eyes == SMALL["eyes"] and back.params["r_min"] == 100.0
    assert back.params["seed"] == 2 and back.params["mode"] == "single"


@pytest.mark.slow
def test_csv_layout_and_appendix_loader(tmp_path, paper_single):
    path = tmp_path / "dataset.csv"
    D.save(paper_single, path)
    text = path.read_text()
    first = text.split("\n", 1)[0].split(",")
    assert len(first) == 723 and set(first[:720]) <= {"0", "1"}
    assert "\r" not in text and text.endswith("\n") and not text[0].isalpha()
    # The paper's Appendix A/B loading code, as printed (np.float is gone: float)
    x, r, fi = [], [], []
    with open(path) as file:
        reader = csv.reader(file, delimiter=",")
        for row in reader:
            x.append(row[:720])
            r.append(row[720])
            fi.append(row[721])
    x, r, fi = np.array(x).astype(np.int64), np.array(r).astype(float), np.array(fi).astype(float)
    assert x.shape == (len(paper_single), 720)
    np.testing.assert_array_equal(x, paper_single.bits)
    np.testing.assert_array_equal(r, paper_single.r)  # floats round-trip exactly
    np.testing.assert_array_equal(fi, paper_single.phi)


def test_csv_without_g_column_is_read(tmp_path):
    ds = D.generate(50, seed=1, **SMALL)
    lines = [
        ",".join(map(str, np.concatenate([a, b]).astype(int))) + f",{float(r)!r},{float(p)!r}"
        for a, b, r, p in zip(ds.omega_a, ds.omega_b, ds.r, ds.phi, strict=True)
    ]
    path = tmp_path / "nog.csv"
    path.write_text("\r\n".join(lines) + "\r\n")
    back = D.load(path)
    assert back.m == 64 and np.isnan(back.g).all()
    _same_dataset(back, ds, with_g=False)


@pytest.mark.parametrize(
    "mutate, where",
    [
        (lambda rows: rows[2].__setitem__(5, "2"), "line 3, column 6: bit must be 0 or 1"),
        (lambda rows: rows[1].__setitem__(65, "abc"), "line 2, column 66: not a number"),
        (lambda rows: rows[3].pop(), "line 4, column 67: expected 67 columns, found 66"),
        (lambda rows: rows[0].__setitem__(64, "nan"), "line 1, column 65: not a finite"),
    ],
)
def test_malformed_csv_names_line_and_column(tmp_path, mutate, where):
    path = tmp_path / "d.csv"
    D.save(D.generate(20, seed=1, **SMALL), path)
    rows = [ln.split(",") for ln in path.read_text().splitlines()]
    mutate(rows)
    path.write_text("\n".join(",".join(r) for r in rows) + "\n")
    with pytest.raises(EyevizError) as info:
        D.load(path)
    assert where in str(info.value) and "\n" not in str(info.value)


def test_load_refuses_wrong_files(tmp_path):
    with pytest.raises(EyevizError, match="no such data set"):
        D.load(tmp_path / "missing.csv")
    (tmp_path / "bad.npz").write_bytes(b"not a zip")
    with pytest.raises(EyevizError, match="not an eyeviz NPZ"):
        D.load(tmp_path / "bad.npz")
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(EyevizError, match="empty"):
        D.load(tmp_path / "empty.csv")


# --- bad input and interruption ------------------------------------------------------


@pytest.mark.parametrize(
    "kw, msg",
    [
        (dict(n=0), "n must be an integer >= 1 and <= 1000000000, got 0"),
        (dict(n=10, r_min=5000, r_max=1000), "r_min must be < r_max"),
        (dict(n=10, r_min=1000, r_max=1000), "r_min must be < r_max"),
        (dict(n=10, g_max=0), "g_max must be a finite number > 0, got 0"),
        (dict(n=10, g_max=4.0), "no feature can be visible"),
        (dict(n=10, r_min=-1), "r_min must be a finite number > 0, got -1"),
        (dict(n=10, mode="triple"), "mode must be"),
        (
            dict(n=10, eyes=EyePair(40, 39.9, 4), r_min=100, r_max=200, g_max=90),
            "no visible feature fits in the BFV",
        ),
        (dict(n=10, r_max=float("nan")), "r_max must be a finite number > 0, got nan"),
    ],
)
def test_bad_parameters_refused(kw, msg):
    with pytest.raises(EyevizError, match=msg):
        D.generate(**kw)


def test_cli_refuses_bad_parameters_before_any_work(tmp_path, eyeviz_main):
    out = tmp_path / "x.csv"
    for args, msg in [
        (["-n", "0"], "n must be an integer >= 1 and <= 1000000000, got 0"),
        (["-n", "5", "--r-min", "3000", "--r-max", "2000"], "r_min must be < r_max"),
        (["-n", "5", "--g-max", "-1"], "g_max must be a finite number > 0"),
        (["-n", "5", "--g-max", "1"], "no feature can be visible"),
        (["-n", "5", "--m", "7"], "m must be an even integer"),
    ]:
        res = eyeviz_main("generate", *args, "-o", out)  # the refusal is the point
        assert res.returncode == 2, res.stderr
        assert msg in res.stderr and res.stderr.count("\n") == 1, res.stderr
        assert "Traceback" not in res.stderr
    assert list(tmp_path.iterdir()) == []


def test_cli_writes_npz_and_csv(tmp_path, eyeviz_main):
    for name in ("a.npz", "a.csv"):  # in this process: the files are the point
        res = eyeviz_main(
            *[
                "generate",
                "-n",
                "300",
                "--mode",
                "multi",
                "--seed",
                "4",
                "--m",
                "64",
                "--h",
                "30",
                "--l",
                "10",
                "--r-min",
                "100",
                "--r-max",
                "400",
                "--g-max",
                "60",
                "-o",
                str(tmp_path / name),
            ]
        )
        assert res.returncode == 0, res.stderr
    a, b = D.load(tmp_path / "a.npz"), D.load(tmp_path / "a.csv")
    _same_dataset(a, b)
    _same_dataset(a, D.generate(300, mode="multi", seed=4, **SMALL))


def test_interrupted_write_leaves_no_file(tmp_path):
    out = tmp_path / "big.csv"
    seen = []

    def stop(k):
        seen.append(k)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        D.write(out, 5 * D.CHUNK, progress=stop)
    assert seen and list(tmp_path.iterdir()) == []


def test_ctrl_c_on_the_command_leaves_no_file(tmp_path):
    out = tmp_path / "big.csv"
    proc = subprocess.Popen(
        [*EYEVIZ, "generate", "-n", "5000000", "-o", str(out), "--quiet"],
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            parts = [p for p in tmp_path.iterdir() if ".part" in p.name]
            if parts and parts[0].stat().st_size > 0:
                break
            time.sleep(0.02)
        else:
            pytest.fail("the command never started writing")
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "no partial output" in err
    assert list(tmp_path.iterdir()) == []


def test_existing_output_survives_failed_run(tmp_path):
    out = tmp_path / "keep.csv"
    out.write_text("precious\n")

    def stop(k):
        raise OSError("No space left on device")

    with pytest.raises(OSError):
        D.write(out, 100, progress=stop)
    assert out.read_text() == "precious\n" and len(list(tmp_path.iterdir())) == 1
    assert os.stat(out).st_size == 9


def test_import_is_light():
    code = (
        "import sys, eyeviz.dataset; bad = {'torch', 'PyQt5', 'pyvista', 'matplotlib', "
        "'tqdm'} & set(sys.modules); print(sorted(bad))"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert res.stdout.strip() == "[]", res.stdout + res.stderr


def test_file_mode_respects_umask(tmp_path):
    D.write(tmp_path / "m.npz", 10)
    mode = os.stat(tmp_path / "m.npz").st_mode & 0o777
    umask = os.umask(0)
    os.umask(umask)
    assert mode == 0o666 & ~umask
    assert Path(tmp_path / "m.npz").stat().st_size > 0


def test_float_text_is_printf_17g_and_round_trips():
    from eyeviz.dataset.io import format_g17

    rng = np.random.default_rng(0)
    edges = [
        0.0,
        -0.0,
        1.0,
        0.1,
        1e-4,
        9.9999999999999995e-5,
        1e16,
        1e17,
        9.999999999999999e16,
        1000.0,
        0.5,
        float("nan"),
        float("inf"),
        -float("inf"),
        5e-324,
        1e300,
        -3.25,
        2.0**53 + 2,
        np.nextafter(1e-4, 0),
        np.nextafter(10.0, 0),
        np.nextafter(1.0, 2),
    ]
    p10 = 10.0 ** np.arange(-8, 20)
    v = np.concatenate(
        [
            edges,
            rng.uniform(1000, 5000, 20000),
            rng.uniform(0, 3.2, 20000),
            10 ** rng.uniform(-8, 20, 20000) * rng.choice([-1, 1], 20000),
            np.arange(-300, 300) / 8.0,
            p10,
            np.nextafter(p10, 0),
            np.nextafter(p10, np.inf),
        ]
    )
    chars, lens = format_g17(v)
    got = [bytes(chars[i, : lens[i]]).decode() for i in range(len(v))]
    assert got == [format(x, ".17g") for x in v.tolist()]
    assert all(float(t) == x for t, x in zip(got, v.tolist(), strict=True) if x == x)


@pytest.mark.parametrize("name", ["full.csv", "full.npz"])
def test_full_disk_leaves_no_file(tmp_path, name):
    # RLIMIT_FSIZE makes write() fail with EFBIG past 5 MB, as a full disk fails it with
    # ENOSPC; the error must surface from the writer thread and remove the temporary file.
    import resource

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (5_000_000, 5_000_000))

    res = subprocess.run(
        [*EYEVIZ, "generate", "-n", "300000", "-o", str(tmp_path / name), "--quiet"],
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=limit,
    )
    assert res.returncode == 2, res.stderr
    assert "File too large" in res.stderr and res.stderr.count("\n") == 1, res.stderr
    assert list(tmp_path.iterdir()) == []


def test_generator_takes_the_one_domain_record():
    from eyeviz.core.domain import Domain

    dom = Domain(h=30, l=10, m=360, r_min=500, r_max=2000, g_max=200)
    a = D.generate(200, dom, seed=4)
    b = D.generate(200, EyePair(30, 10, 360), 500, 2000, 200, seed=4)
    assert np.array_equal(a.omega_a, b.omega_a) and np.array_equal(a.r, b.r)
    assert a.eyes.m == 360 and (a.r >= 500).all() and (a.r <= 2000).all()
    p = D.make_params(dom, mode="multi", seed=1)
    assert p.domain == dom and p.mode == "multi"
    assert D.GenParams.from_domain(dom).domain == dom
    assert D.make_params(dom, r_max=1500).r_max == 1500  # an explicit range wins
    with pytest.raises(EyevizError, match="r_min must be < r_max"):
        D.make_params(dom, r_max=400)


def test_defaults_are_tables_3_and_4_written_once():
    from eyeviz.core.domain import DEFAULTS, PAPER_DOMAIN

    assert DEFAULTS == {
        "h": 40.0,
        "l": 20.0,
        "m": 720,
        "r_min": 1000.0,
        "r_max": 5000.0,
        "g_max": 500.0,
    }
    p = D.make_params()
    assert p.domain == PAPER_DOMAIN and D.PAPER_EYES == PAPER_DOMAIN.eyes


def _imports(module) -> set[str]:
    import ast

    tree = ast.parse(Path(module.__file__).read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module + ":" + ",".join(a.name for a in node.names))
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return out


def test_records_module_is_a_leaf_and_io_does_not_import_the_sampler():
    import importlib

    from eyeviz.dataset import io, records

    assert not any(i.startswith("eyeviz.dataset") for i in _imports(records))
    mods = [io]
    if importlib.util.find_spec("eyeviz.dataset.reader"):
        mods.append(importlib.import_module("eyeviz.dataset.reader"))
    submodules = {"io", "reader", "records"}
    for mod in mods:
        bad = [
            i
            for i in _imports(mod)
            if "algorithm1" in i
            or (
                i.startswith("eyeviz.dataset:")
                and not set(i.split(":")[1].split(",")) <= submodules
            )
        ]
        assert bad == [], (mod.__name__, bad)
