"""Outputs and study locks act on the resolved file (issue 25 item 5): a symlinked output
is written through (the link stays a link), a symlink or hard link to a table under study
is refused like the table itself."""

from __future__ import annotations

import os

import pytest

from eyeviz import EyevizError
from eyeviz.files.atomic import atomic_output
from eyeviz.study.runner import _exclusive


def test_a_symlinked_output_is_written_through(tmp_path):
    real = tmp_path / "data" / "table.csv"
    real.parent.mkdir()
    real.write_text("old\n")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    with atomic_output(link) as tmp:
        tmp.write_text("new\n")
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert real.read_text() == "new\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no stray part


def test_a_dangling_symlink_creates_its_target(tmp_path):
    real = tmp_path / "t.csv"
    link = tmp_path / "l.csv"
    link.symlink_to(real)
    with atomic_output(link) as tmp:
        tmp.write_text("x\n")
    assert link.is_symlink() and real.read_text() == "x\n"


def test_a_symlink_to_a_table_under_study_is_refused(tmp_path):
    real = tmp_path / "study.csv"
    real.write_text("")
    link = tmp_path / "alias.csv"
    link.symlink_to(real)
    with _exclusive(real), pytest.raises(EyevizError, match="another study is writing"):
        with _exclusive(link):
            pass
    with _exclusive(link):  # released: taken again, through the link
        pass


def test_a_hard_link_to_a_table_under_study_is_refused(tmp_path):
    real = tmp_path / "study.csv"
    real.write_text("")
    (tmp_path / "other").mkdir()
    hard = tmp_path / "other" / "copy.csv"
    os.link(real, hard)
    with _exclusive(real), pytest.raises(EyevizError, match="hard link"):
        with _exclusive(hard):
            pass
    with _exclusive(hard):
        pass
