"""Helpers shared by the study tests."""

import csv
import io

import pytest


@pytest.fixture
def edit_field():
    """``edit(path, line_no, columns, column, value)``: set one field of one line of a
    study table (planar or 3D: its ``columns``), written back as CSV."""

    def edit(path, line_no: int, columns: tuple[str, ...], column: str, value: str) -> None:
        lines = path.read_text().splitlines()
        fields = next(csv.reader([lines[line_no - 1]]))
        fields[columns.index(column)] = value
        buf = io.StringIO()
        csv.writer(buf, lineterminator="").writerow(fields)
        lines[line_no - 1] = buf.getvalue()
        path.write_text("\n".join(lines) + "\n")

    return edit
