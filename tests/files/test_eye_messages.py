"""The .eye reader's one-line messages say what is wrong in the file's own words: a NaN
token is 'not a number' (not 'not 8 numbers' on a line of 8 tokens), and an acceptance
angle is shown as a number, not as numpy's repr."""

from __future__ import annotations

import pytest

from eyeviz import EyevizError
from eyeviz.measured import load_eyes

GOOD = "-1 0 0 -1 0 0 0.05 0.2\n1 0 0 1 0 0 0.05 0.2\n"


@pytest.mark.parametrize(
    ("row", "want"),
    [
        ("1 nan 0 1 0 0 0.05 0.2", "line 3: 'nan' is not a number"),
        ("1 0 0 1 inf 0 0.05 0.2", "line 3: 'inf' is not a number"),
        ("1 0 0 1 0 0 0 0.2", "line 3: acceptance angle 0.0 rad is not in (0, pi)"),
        ("1 0 0 1 0 0 3.5 0.2", "line 3: acceptance angle 3.5 rad is not in (0, pi)"),
    ],
)
def test_bad_rows_are_named_plainly(tmp_path, row, want):
    path = tmp_path / "bad.eye"
    path.write_text(GOOD + row + "\n")
    with pytest.raises(EyevizError) as info:
        load_eyes(path)
    text = str(info.value)
    assert "\n" not in text and "np." not in text
    assert text.endswith(want), text
