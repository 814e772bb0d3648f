"""Executing a notebook outside Jupyter: nbclient's client, made safe for the chapters' widgets.

nbclient waits for each cell's reply with one long read of the kernel's shell channel. When a cell
opens widgets (chapter 8's tuning sliders), that read sometimes does not wake up although the reply
has arrived: the kernel is idle, and the reply is picked up only by the last, zero-length read at
the cell's timeout — so a cell of two seconds takes ten minutes, and nothing fails (nbclient issue
#312). Measured with the slider cell and both cores loaded: 5 of 25 and 2 of 20 runs stalled for
exactly the timeout; through :func:`notebook_client`, which reads in half-second waits up to the same
deadline, 0 of 25 and 0 of 20. The grader, the mutation runs, the notebook refresh and the chapter
timing all execute through it.
"""

from __future__ import annotations

import time
from pathlib import Path
from queue import Empty

from nbclient import NotebookClient

from quadlib.validation import as_positive

__all__ = ["notebook_client"]

POLL_S = 0.5
"""The longest single wait for a message on the shell channel [s]."""


def _read_in_short_waits(channel) -> None:
    """Make ``channel.get_msg(timeout)`` wait in :data:`POLL_S` steps up to the same deadline."""
    read = channel.get_msg

    async def get_msg(timeout=None):
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            wait = POLL_S if deadline is None else min(POLL_S, max(0.0, deadline - time.monotonic()))
            try:
                return await read(timeout=wait)
            except Empty:
                if deadline is not None and time.monotonic() >= deadline:
                    raise

    channel.get_msg = get_msg


def notebook_client(nb, directory, timeout_s: float = 600.0, allow_errors: bool = False) -> NotebookClient:
    """An nbclient ``NotebookClient`` for notebook ``nb`` (an ``nbformat`` node), running its kernel
    in ``directory``, each cell limited to ``timeout_s`` [s]; ``allow_errors`` runs on past a failing
    cell. Use it as nbclient's (``.execute()``, or ``setup_kernel()`` and ``execute_cell``)."""
    directory = Path(directory)
    if not directory.is_dir():
        raise NotADirectoryError(f"directory: expected an existing folder, got {str(directory)!r}")
    client = NotebookClient(nb, timeout=as_positive("timeout_s", timeout_s), kernel_name="python3",
                            allow_errors=bool(allow_errors), resources={"metadata": {"path": str(directory)}})
    # nbclient calls this hook once the kernel client exists, whether through execute() or setup_kernel()
    client.on_notebook_start = lambda notebook: _read_in_short_waits(client.kc.shell_channel)
    return client
