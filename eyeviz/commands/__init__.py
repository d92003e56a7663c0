"""Sub-commands of the ``eyeviz`` command line.

Each module here defines ``NAME``, ``HELP``, ``add_arguments(parser)`` and
``run(args) -> int`` and is discovered by :mod:`eyeviz.cli`. Modules import nothing heavy
at the top (no Qt, VTK or torch): ``eyeviz --help`` must stay instant.
"""
