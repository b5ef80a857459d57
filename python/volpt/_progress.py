"""``render(progress=True)``: a one-line progress bar on standard error."""

import sys
import time


class Bar:
    """Called as ``bar(done, total)`` with paths traced; writes ``\\r`` updates to stderr."""

    def __init__(self, stream=None):
        self.stream = stream if stream is not None else sys.stderr
        self.start = time.monotonic()
        self.finished = False

    def __call__(self, done: int, total: int) -> None:
        if self.finished:
            return
        fraction = done / total if total else 1.0
        width = 30
        filled = int(fraction * width)
        elapsed = time.monotonic() - self.start
        line = f"\rvolpt [{'#' * filled}{'.' * (width - filled)}] {100 * fraction:5.1f}% {elapsed:6.1f} s"
        if done >= total:
            line += "\n"
            self.finished = True
        self.stream.write(line)
        self.stream.flush()

    def note(self, text: str) -> None:
        self.stream.write(f"\r{text}\n")
        self.stream.flush()
