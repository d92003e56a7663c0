"""Painters of the teaching layers (Figures 3b, 5-6), drawing ONLY from a Frame: a thin
re-export of :mod:`eyeviz.render.vtk.layers.bfv`, ``.tangents`` and ``.sectors``."""

from eyeviz.render.vtk.layers.bfv import BFV_SLOTS, BfvPainter
from eyeviz.render.vtk.layers.sectors import RAY_SLOTS, SectorPainter
from eyeviz.render.vtk.layers.tangents import TangentPainter

__all__ = ["BfvPainter", "SectorPainter", "TangentPainter", "BFV_SLOTS", "RAY_SLOTS"]
