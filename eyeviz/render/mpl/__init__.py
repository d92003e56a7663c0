"""Matplotlib painters: true-vector figures drawn from the scene model."""
