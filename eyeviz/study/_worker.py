"""Preloaded into the study's local worker processes (``LocalCluster(preload=...)``).

A Ctrl-C in the terminal reaches the whole process group: once started, the workers
ignore it (the parent closes the cluster and keeps the finished points), and so does a
worker the nanny restarts after a crash. A worker still starting up when Ctrl-C comes
may print its own KeyboardInterrupt before it goes.
"""

from __future__ import annotations

import signal
import threading


def dask_setup(worker=None) -> None:
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
