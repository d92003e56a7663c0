"""Outputs that are not regular files (issue 35, item 1): a character device (a copy of
/dev/null made with mknod) or a FIFO is written through and stays what it was; a FIFO
with no reader, a folder or a block device is refused in one line before any work. Every
command that writes a file goes through :func:`eyeviz.files.atomic.atomic_output`; the
ones here are driven end to end."""

from __future__ import annotations

import os
import select
import socket
import stat
import threading

import pytest

from eyeviz import EyevizError, cli
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import sparse3d
from eyeviz.files.atomic import atomic_output
from eyeviz.resources import scenes_dir


def _null_copy(path):
    """A character device like /dev/null (1, 3); tests that need one run as root."""
    try:
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    except PermissionError:
        pytest.skip("mknod needs root (CAP_MKNOD)")
    return path


class _Reader(threading.Thread):
    """Reads a FIFO to its end, as `cat FIFO > file` would.

    The read end is opened here, before the command runs, so the command always finds its
    reader (a thread that had not yet reached open() made the command refuse the FIFO on a
    loaded machine). poll() waits for data; it reports a hang-up only after a writer has
    come and gone, so the read loop ends at the writer's close, not before it opens."""

    def __init__(self, fifo):
        super().__init__(daemon=True)
        self.fd = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)
        self.data = b""
        self.start()

    def run(self):
        poller = select.poll()
        poller.register(self.fd, select.POLLIN)
        chunks = []
        try:
            while True:
                poller.poll()
                try:
                    chunk = os.read(self.fd, 1 << 16)
                except BlockingIOError:
                    continue
                if not chunk:
                    break
                chunks.append(chunk)
        finally:
            os.close(self.fd)
        self.data = b"".join(chunks)


@pytest.fixture(scope="module")
def sky(tmp_path_factory):
    p = tmp_path_factory.mktemp("sky") / "sky.npz"
    sparse3d.write3d(p, 8, Domain3D(nside=4), seed=3)
    return p


def _commands(sky, out):
    return {
        "predict": ["predict", "-e", "analytic3d", str(sky), "-o", out],
        "generate_csv": ["generate", "-n", "5", "--seed", "2", "-o", out, "--quiet"],
        "generate_3d": ["generate", "--nside", "4", "-n", "5", "-o", out, "--quiet"],
        "snapshot": ["snapshot", str(scenes_dir() / "default.toml"), "-o", out],
    }


SUFFIX = {"predict": ".csv", "generate_csv": ".csv", "generate_3d": ".npz", "snapshot": ".svg"}


@pytest.mark.parametrize("command", list(SUFFIX))
def test_a_character_device_is_written_through(tmp_path, capsys, sky, command):
    dev = _null_copy(tmp_path / f"null{SUFFIX[command]}")
    rc = cli.main(_commands(sky, str(dev))[command])
    assert rc == 0, capsys.readouterr().err
    st = os.lstat(dev)
    assert stat.S_ISCHR(st.st_mode) and st.st_rdev == os.makedev(1, 3)
    assert sorted(p.name for p in tmp_path.iterdir()) == [dev.name]


@pytest.mark.parametrize("command", list(SUFFIX))
def test_a_fifo_is_written_through_whole(tmp_path, capsys, sky, command):
    fifo = tmp_path / f"pipe{SUFFIX[command]}"
    os.mkfifo(fifo)
    reader = _Reader(fifo)
    rc = cli.main(_commands(sky, str(fifo))[command])
    reader.join(60)
    assert rc == 0, capsys.readouterr().err
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    head = {".csv": b"", ".npz": b"PK\x03\x04", ".svg": b"<?xml"}[SUFFIX[command]]
    assert reader.data.startswith(head) and len(reader.data) > 20
    if command == "predict":
        assert reader.data.startswith(b"r_hat,azimuth_hat,elevation_hat,flagged\n")
        assert reader.data.count(b"\n") == 9  # the header and the 8 rows: whole
    assert sorted(p.name for p in tmp_path.iterdir()) == [fifo.name]


def test_a_fifo_with_no_reader_is_refused_in_one_line(tmp_path, capsys, sky):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    rc = cli.main(["predict", "-e", "analytic3d", str(sky), "-o", str(fifo)])
    err = capsys.readouterr().err
    assert rc == 2 and err.strip().splitlines() == [
        f"eyeviz: error: output {str(fifo)!r} is a FIFO with no reader; start its reader first"
    ]
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_a_link_to_a_device_stays_a_link_to_it(tmp_path, capsys, sky):
    dev = _null_copy(tmp_path / "null")
    link = tmp_path / "out.csv"
    link.symlink_to(dev)
    rc = cli.main(["predict", "-e", "analytic3d", str(sky), "-o", str(link)])
    assert rc == 0, capsys.readouterr().err
    assert link.is_symlink() and stat.S_ISCHR(os.lstat(dev).st_mode)


def test_what_cannot_be_written_through_is_refused(tmp_path):
    (tmp_path / "dir.csv").mkdir()
    loop = tmp_path / "loop.csv"
    loop.symlink_to(loop)
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(tmp_path / "sock.csv"))
    try:
        cases = {"dir.csv": "a directory", "sock.csv": "a socket", "loop.csv": "link"}
        try:
            os.mknod(tmp_path / "blk.csv", 0o600 | stat.S_IFBLK, os.makedev(7, 0))
            cases["blk.csv"] = "a block device"
        except PermissionError:
            pass
        for name, words in cases.items():
            with pytest.raises(EyevizError, match=words), atomic_output(tmp_path / name):
                raise AssertionError("no work may start")
        assert (tmp_path / "dir.csv").is_dir() and loop.is_symlink()
        assert stat.S_ISSOCK(os.lstat(tmp_path / "sock.csv").st_mode)
    finally:
        sock.close()


def test_a_report_or_a_study_into_a_device_is_refused(tmp_path, capsys):
    dev = _null_copy(tmp_path / "null.csv")
    rc = cli.main(["report", "stability", "-o", str(dev)])
    err = capsys.readouterr().err
    assert rc == 2 and ("is not a folder" in err or "is not a directory" in err), err
    assert len(err.strip().splitlines()) == 1, err
    rc = cli.main(["study", "-o", str(dev), "--h", "40", "--l", "20", "--m", "720"])
    err = capsys.readouterr().err
    assert rc == 2 and "is not a regular file" in err, err
    assert stat.S_ISCHR(os.lstat(dev).st_mode)
