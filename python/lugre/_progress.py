"""Progress lines on stderr for steps longer than a second (only on a terminal)."""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TextIO

__all__ = ["Progress"]


class Progress:
    """Announces a step on ``stream`` once it has run for ``after`` seconds, and its end.

    Parameters
    ----------
    enabled : bool, optional
        Default: ``stream`` is a terminal.
    stream : file, optional
        Default: ``sys.stderr``.
    after : float
        Seconds a step runs before it is announced.
    """

    def __init__(self, enabled: bool | None = None, stream: TextIO | None = None,
                 after: float = 1.0) -> None:
        self.stream = stream if stream is not None else sys.stderr
        if enabled is None:
            isatty = getattr(self.stream, "isatty", None)
            enabled = bool(isatty and isatty())
        self.enabled = enabled
        self.after = after

    @contextmanager
    def step(self, what: str) -> Iterator[None]:
        """Run the ``with`` body as the step ``what``."""
        if not self.enabled:
            yield
            return
        start = time.monotonic()
        shown = threading.Event()
        lock = threading.Lock()

        def announce() -> None:
            with lock:
                print(f"{what} ...", file=self.stream, flush=True)
                shown.set()

        timer = threading.Timer(self.after, announce)
        timer.daemon = True
        timer.start()
        try:
            yield
        finally:
            timer.cancel()
            with lock:
                if shown.is_set():
                    print(f"{what}: done in {time.monotonic() - start:.1f} s",
                          file=self.stream, flush=True)
