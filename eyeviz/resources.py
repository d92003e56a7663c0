"""The shipped assets (scenes, models), found with :mod:`importlib.resources`.

In a source checkout ``eyeviz/assets`` is a link to the top-level ``assets/`` folder; in a
wheel the files are package data of :mod:`eyeviz`. Nothing here writes: the shipped assets
are read-only for eyeviz (training and saving go elsewhere unless asked explicitly).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

__all__ = ["assets_dir", "models_dir", "scene_path", "scenes_dir"]


def assets_dir() -> Path:
    """The folder of the shipped assets."""
    return Path(str(resources.files("eyeviz") / "assets"))


def scenes_dir() -> Path:
    """The folder of the bundled teaching scenes (``*.toml``)."""
    return assets_dir() / "scenes"


def models_dir() -> Path:
    """The folder of the shipped estimator models (compact, bayes, paper metadata)."""
    return assets_dir() / "models"


def scene_path(name: str) -> Path:
    """A bundled scene by name, with or without ``.toml`` (``scene_path("default")``)."""
    stem = name[:-5] if name.endswith(".toml") else name
    return scenes_dir() / f"{stem}.toml"
