"""A minimal undo stack for the model tests (the window uses a QUndoStack)."""


class Undo:
    """A minimal undo stack (before, after, text) like the window's QUndoStack."""

    def __init__(self, model):
        self.steps = []
        self.model = model
        model.push = self.push

    def push(self, before, after, text, merge_key=None):
        self.steps.append((before.copy(), after.copy(), text))
        self.model.set_scene(after)

    def undo(self):
        before, _, _ = self.steps.pop()
        self.model.set_scene(before)
