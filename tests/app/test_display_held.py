"""`eyeviz app` under a fresh `xvfb-run` (issue 32.14's benches): the display check's own
X connection was the server's only client and was closed before Qt connected; an Xvfb
resets when its last client leaves, and Qt's connection sometimes met the reset ("could
not connect to display", SIGABRT: 1 run in 16-40). The check now keeps its connection.

Seen through the reset itself: an atom interned by a second connection survives that
connection's close only while another client (the check's) is still connected."""

import os
import shutil
import subprocess
import sys

import pytest

PROBE = r"""
import ctypes, ctypes.util, sys
from eyeviz.app.launch import check_display
x11 = ctypes.CDLL(ctypes.util.find_library("X11"))
x11.XOpenDisplay.restype = ctypes.c_void_p
x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
x11.XInternAtom.restype = ctypes.c_ulong
x11.XInternAtom.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int]
check_display()
d = x11.XOpenDisplay(None)
x11.XInternAtom(d, b"EYEVIZ_PROBE_ATOM", 0)
x11.XCloseDisplay(d)  # the last client, unless the check's is still open: a reset
d = x11.XOpenDisplay(None)
print("kept" if x11.XInternAtom(d, b"EYEVIZ_PROBE_ATOM", 1) else "reset")
"""


def test_the_display_check_keeps_its_connection_so_xvfb_does_not_reset():
    if shutil.which("Xvfb") is None:
        pytest.fail("Xvfb is needed for this test (apt-get install xvfb)")
    r, w = os.pipe()
    server = subprocess.Popen(
        ["Xvfb", "-displayfd", str(w), "-screen", "0", "64x64x24", "-nolisten", "tcp"],
        pass_fds=(w,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(w)
    try:
        with os.fdopen(r) as f:
            number = f.readline().strip()
        assert number, "Xvfb did not start"
        env = dict(os.environ, DISPLAY=f":{number}", QT_QPA_PLATFORM="xcb")
        out = subprocess.run(
            [sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, timeout=60
        )
        assert out.returncode == 0, out.stderr
        assert out.stdout.strip() == "kept"
    finally:
        server.terminate()
        server.wait(10)
