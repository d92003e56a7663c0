"""Settings for the whole suite.

Hypothesis' default deadline (200 ms per example) is a wall-clock assertion: on a loaded
machine, or beside another pytest-xdist worker, a correct example can take longer and
fail. No test here asserts on time (speed claims live in ``scripts/bench_*.py``); a hang
is caught by pytest-timeout (``timeout`` in pyproject's ``[tool.pytest.ini_options]``).
"""

import pytest
from hypothesis import settings

settings.register_profile("eyeviz", deadline=None)
settings.load_profile("eyeviz")


def pytest_collection_modifyitems(config, items):
    """Under pytest-xdist, the modules holding a test marked ``slow`` run first (each
    module's tests together and in their order, so module-scope fixtures are made once
    per worker): the long tests are then spread while there is work for both workers,
    and each stage ends on short ones, its workers finishing together rather than one
    waiting for a long test of the other (issue 31: the CI's 10 minutes). Without xdist
    the order is pytest's."""
    if not hasattr(config, "workerinput"):  # a pytest-xdist worker's collection
        return
    slow_modules = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.path not in slow_modules)  # stable


@pytest.fixture(scope="session")
def toy_pair():
    """A small measured pair: :func:`toy_measured_pair`."""
    return toy_measured_pair()


@pytest.fixture(scope="session")
def honeybee():
    """The shipped honeybee (AM_60185, 2 x 3187 facets), loaded once."""
    from eyeviz.measured import load_eyes, shipped_eye

    return load_eyes(shipped_eye("AM_60185-real.eye"))


def toy_measured_pair(n_dirs: int = 600, acceptance: float = 0.2):
    """A small measured pair (docs/measured.md) with a wide frontal binocular field: per
    eye, lenses on a sphere of radius 0.5 about (-/+2, 0, 0) looking outwards, the front
    directions (y > 0.2) of a Fibonacci sphere. Fast enough for data sets of a few rows."""
    import numpy as np

    from eyeviz.core.measured import MeasuredEye, MeasuredEyePair

    k = np.arange(n_dirs) + 0.5
    z = 1 - 2 * k / n_dirs
    phi = np.pi * (1 + 5**0.5) * k
    d = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], 1)
    d = d[d[:, 1] > 0.2]
    eyes = [
        MeasuredEye(np.array([sx, 0.0, 0.0]) + 0.5 * d, d, np.full(len(d), acceptance), name=nm)
        for sx, nm in ((-2.0, "A"), (2.0, "B"))
    ]
    return MeasuredEyePair(eyes[0], eyes[1], name="toy", source="tests/conftest.py")


class ToyEyes:
    """docs/extending.md's toy eye model in space: seven facets per eye, a new kind.

    Each eye has a central facet and six around it (``tilt`` away), their axes turned
    ``squint`` towards the other eye, lenses at distance ``l`` from the eye's centre (-h or
    +h on x) along their axes, each seeing a cone of full angle ``acceptance``. Its
    geometry is written here, independently of the package: a facet sees a ball (c, g)
    iff the ball's distance from the facet's cone (apex the lens, axis a, half-angle al)
    is at most g, with d = |c - p| and t = angle(c - p, a): 0 for t <= al, d sin(t - al)
    for t < al + pi/2, else d. It implements the protocol :class:`eyeviz.core.eyes.EyeModel`
    and gives its facets (``facets(eye)``), which is all the pipeline asks of it.
    """

    kind = "toy"
    dims = 3

    def __init__(
        self, h: float = 2.0, l: float = 0.5, tilt: float = 0.3, acceptance: float = 0.45
    ) -> None:
        self.h, self.l, self.tilt, self.acceptance = h, l, tilt, acceptance  # noqa: E741
        self.squint = 0.5

    @property
    def facet_counts(self) -> tuple[int, int]:
        return (7, 7)

    @property
    def design(self) -> dict[str, float]:
        return {"h": self.h, "l": self.l, "tilt": self.tilt, "acceptance": self.acceptance}

    def facets(self, eye: str):
        import numpy as np

        t = np.r_[0.0, np.full(6, self.tilt)]
        p = np.r_[0.0, np.arange(6) * np.pi / 3]
        u = np.c_[np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)]
        sx = -1.0 if eye == "A" else 1.0
        c, s = np.cos(sx * self.squint), np.sin(sx * self.squint)
        u = np.c_[c * u[:, 0] - s * u[:, 1], s * u[:, 0] + c * u[:, 1], u[:, 2]]
        return u * self.l + [sx * self.h, 0.0, 0.0], u, np.full(7, self.acceptance)

    def _eye(self, eye: str, x, y, z, g):
        import numpy as np

        pos, ax, acc = self.facets(eye)
        v = np.stack(np.broadcast_arrays(x, y, z), -1)[..., None, :] - pos  # (..., 7, 3)
        d = np.linalg.norm(v, axis=-1)
        t = np.arccos(np.clip((v * ax).sum(-1) / np.maximum(d, 1e-300), -1, 1))
        al = acc / 2
        dist = np.where(t <= al, 0.0, np.where(t < al + np.pi / 2, d * np.sin(t - al), d))
        return dist <= np.asarray(g)[..., None], d.min(-1) <= np.asarray(g)

    def bitmaps(self, x, y, z, g):
        return self._eye("A", x, y, z, g)[0], self._eye("B", x, y, z, g)[0]

    def visible(self, x, y, z, g):
        a, b = self.bitmaps(x, y, z, g)
        return a.sum(-1) >= 2, b.sum(-1) >= 2

    def overlaps_eye(self, x, y, z, g):
        return self._eye("A", x, y, z, g)[1], self._eye("B", x, y, z, g)[1]

    def in_bfv(self, x, y, z, g):
        (va, vb), (oa, ob) = self.visible(x, y, z, g), self.overlaps_eye(x, y, z, g)
        return va & vb & ~oa & ~ob


@pytest.fixture(scope="session")
def toy_eyes() -> ToyEyes:
    """docs/extending.md's toy eye model in space (:class:`ToyEyes`)."""
    return ToyEyes()


def _read_predictions3d(pred, npz):
    """``eyeviz predict``'s CSV of a sparse 3D data set ``npz``, checked: the header, one
    finite row per data row, r_hat within the domain. Returns (data set, values (n, 4),
    each row's direction error in radians, the true unit directions from the origin)."""
    import csv

    import numpy as np

    from eyeviz.dataset import sparse3d

    with open(pred, newline="") as f:
        rows = list(csv.reader(f))
    ds = sparse3d.load3d(npz)
    vals = np.array(rows[1:], float)
    assert rows[0] == ["r_hat", "azimuth_hat", "elevation_hat", "flagged"]
    assert vals.shape == (len(ds.r), 4) and np.isfinite(vals).all()
    dom = ds.domain
    assert (vals[:, 0] >= dom.r_min).all() and (vals[:, 0] <= dom.r_max).all()
    d_true = np.c_[ds.x, ds.y, ds.z] - np.asarray(dom.origin)
    unit = d_true / np.linalg.norm(d_true, axis=1)[:, None]
    az, el = vals[:, 1], vals[:, 2]
    d_hat = np.c_[np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)]
    err = np.arccos(np.clip(np.einsum("ij,ij->i", d_hat, unit), -1, 1))
    return ds, vals, err, unit


@pytest.fixture
def read_predictions3d():
    """:func:`_read_predictions3d`: a predict CSV of a 3D data set, checked, with errors."""
    return _read_predictions3d


def _eyeviz_main(*args, cwd=None):
    """``eyeviz ARGS`` run in this process through :func:`eyeviz.cli.main`, what the
    command line runs once Python has started: a CompletedProcess with its exit code and
    what it wrote to stdout and stderr (argparse's usage errors exit 2 there too).

    For tests whose point is a command's result (files, exit codes, one-line messages),
    not its process: each subprocess costs a Python start and eyeviz's imports, 1-2
    CPU-seconds (issue 31: the CI's 10 minutes). Signals, import isolation, output written
    below Python (a C library's) and the real entry point keep a process of their own.
    ``cwd``: the working directory meanwhile (relative paths)."""
    import contextlib
    import io
    import subprocess

    from eyeviz.cli import main

    argv = [str(a) for a in args]
    out, err = io.StringIO(), io.StringIO()
    where = contextlib.chdir(cwd) if cwd is not None else contextlib.nullcontext()
    with where, contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse: --help, usage errors
            code = exc.code if isinstance(exc.code, int) else 0 if exc.code is None else 1
            if isinstance(exc.code, str):
                print(exc.code, file=err)
    return subprocess.CompletedProcess(["eyeviz", *argv], code, out.getvalue(), err.getvalue())


@pytest.fixture
def eyeviz_main():
    """:func:`_eyeviz_main`: ``eyeviz ARGS`` in this process, as a CompletedProcess."""
    return _eyeviz_main
