"""Settings are read only from a bounded regular file (issue 35, item 5): a FIFO blocked
the app forever and /dev/zero read until MemoryError. Each is refused in one line and the
app starts with defaults; the refused path is never written."""

from __future__ import annotations

import json
import os
import stat
import threading

import pytest

from eyeviz.app.settings import MAX_BYTES, Settings


def _settings_within(path, seconds=20.0) -> Settings:
    got: list[Settings] = []
    t = threading.Thread(target=lambda: got.append(Settings(path)), daemon=True)
    t.start()
    t.join(seconds)
    assert got, f"reading settings from {path} did not return within {seconds} s"
    return got[0]


def _special(tmp_path, kind):
    if kind == "fifo":
        p = tmp_path / "fifo.json"
        os.mkfifo(p)
        return p
    if kind == "dev_zero":
        return "/dev/zero"
    if kind == "link_to_dev_zero":
        p = tmp_path / "settings.json"
        p.symlink_to("/dev/zero")
        return p
    if kind == "folder":
        p = tmp_path / "settings.json"
        p.mkdir()
        return p
    raise AssertionError(kind)


@pytest.mark.parametrize("kind", ["fifo", "dev_zero", "link_to_dev_zero", "folder"])
def test_a_file_that_is_not_regular_is_refused_in_one_line(tmp_path, capsys, kind):
    path = _special(tmp_path, kind)
    s = _settings_within(path)
    assert s.data == {} and s.refused.endswith("not a regular file")
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [s.refused]
    s.setValue("recent", ["a.toml"])
    s.sync()  # never written over the refused path
    if kind == "fifo":
        assert stat.S_ISFIFO(os.lstat(path).st_mode)


def test_a_regular_file_reads_and_a_large_one_is_refused(tmp_path, capsys):
    p = tmp_path / "s.json"
    p.write_text(json.dumps({"recent": ["x.toml"]}))
    assert Settings(p).value("recent") == ["x.toml"]
    p.write_bytes(b" " * (MAX_BYTES + 1))
    s = Settings(p)
    assert s.data == {} and "larger than" in s.refused
    capsys.readouterr()
