"""The app view's layers, one module each; each draws only a
:class:`eyeviz.model.frame.Frame`."""
