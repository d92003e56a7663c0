"""One painter per layer: each draws one part of a :class:`eyeviz.model.frame.Frame`."""
