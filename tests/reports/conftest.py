import pytest


@pytest.fixture()
def no_paper_weights(tmp_path, monkeypatch):
    """Point the paper weights search at an empty directory (weights may exist locally)."""
    empty = tmp_path / "no_weights"
    empty.mkdir()
    monkeypatch.setenv("EYEVIZ_PAPER_DIR", str(empty))
    monkeypatch.setenv("XDG_CACHE_HOME", str(empty))
    return empty
