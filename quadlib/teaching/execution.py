"""Executing a notebook outside Jupyter: nbclient's client, made safe for the chapters' widgets.

nbclient waits for each cell's reply with one blocking read of the kernel's shell channel. When a
cell opens widgets (chapter 5's tuning sliders) that read sometimes misses the reply and returns
only at the cell's timeout, so a cell of a second runs for ten minutes (nbclient issue #312;
reproduced here under load, 5 runs in 25, each stalling exactly the timeout). :func:`notebook_client`
gives a client that reads in half-second waits up to the same deadline: a reply that arrived is
picked up by the next read, and the timeout still applies. The grader, the mutation runs, the
notebook refresh and the chapter timing all execute through it.
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


class _PolledClient(NotebookClient):
    async def async_start_new_kernel_client(self):
        kc = await super().async_start_new_kernel_client()
        channel = kc.shell_channel
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
        return kc


def notebook_client(nb, directory, timeout_s: float = 600.0, allow_errors: bool = False) -> NotebookClient:
    """An nbclient ``NotebookClient`` for notebook ``nb`` (an ``nbformat`` node), running its kernel
    in ``directory``, each cell limited to ``timeout_s`` [s]; ``allow_errors`` runs on past a failing
    cell. Use it as nbclient's (``.execute()``, or ``setup_kernel()`` and ``execute_cell``)."""
    directory = Path(directory)
    if not directory.is_dir():
        raise NotADirectoryError(f"directory: expected an existing folder, got {str(directory)!r}")
    return _PolledClient(nb, timeout=as_positive("timeout_s", timeout_s), kernel_name="python3",
                         allow_errors=bool(allow_errors), resources={"metadata": {"path": str(directory)}})
