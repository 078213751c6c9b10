"""A process that dies with its parent: the fleet's fork server with the command that started it, each worker with
the fork server.

``kill -9`` of ``ema fleet`` gives its children no chance to clean up: its fork server and its workers, hundreds of
MB each, ran on for minutes. On Linux the kernel sends a process a signal when its parent dies (``prctl``'s
``PR_SET_PDEATHSIG``): each of them asks for SIGKILL then, and checks that its parent had not died already while it
started. Elsewhere nothing is asked (the pool's own pipes still end the workers once idle).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import sys

PR_SET_PDEATHSIG = 1  # linux/prctl.h


def die_with_parent() -> bool:
    """Ask the kernel to kill this process when its parent dies; whether it could (Linux only). A parent gone
    already (this process adopted while it started) ends it now."""
    if not sys.platform.startswith("linux"):
        return False
    parent = os.getppid()
    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    if libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) != 0:
        return False
    if os.getppid() != parent:  # the parent died before the request stood
        os.kill(os.getpid(), signal.SIGKILL)
    return True
