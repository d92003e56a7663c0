"""The Qt-free, VTK-free model: scene, state, predictor, app model and interactions."""
