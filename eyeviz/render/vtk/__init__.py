"""VTK painters: the app's actors, updated in place from the scene model."""
