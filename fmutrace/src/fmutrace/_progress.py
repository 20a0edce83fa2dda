"""A campaign's progress bar on a terminal."""

import sys
import time


class Progress:
    """A progress bar on a terminal, from the moment a campaign has taken
    a few seconds; nothing when the stream is not a terminal."""

    AFTER_SECONDS = 2.0

    def __init__(self, total: int, stream=None):
        self.total, self.stream = total, stream or sys.stderr
        self.enabled = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.started = time.monotonic()
        self.shown = False

    def update(self, done: int, failed: int):
        elapsed = time.monotonic() - self.started
        if not self.enabled or (elapsed < self.AFTER_SECONDS and done < self.total):
            return
        if not self.shown and done == self.total:
            return
        width = 30
        filled = width * done // max(1, self.total)
        self.stream.write(
            f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{self.total} cases, {failed} failing, {elapsed:.0f} s "
        )
        self.stream.flush()
        self.shown = True

    def close(self):
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()


class SampleProgress:
    """A long single case's progress on a terminal: samples done, their
    rate and the time left, from the moment it has taken a few seconds;
    nothing when the stream is not a terminal."""

    AFTER_SECONDS = 2.0
    EVERY_SECONDS = 0.5

    def __init__(self, total: int, stream=None):
        self.total, self.stream = total, stream or sys.stderr
        self.enabled = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.started = self.drawn = time.monotonic()
        self.shown = False

    def update(self, done: int):
        if not self.enabled:
            return
        now = time.monotonic()
        elapsed = now - self.started
        if elapsed < self.AFTER_SECONDS or (now - self.drawn < self.EVERY_SECONDS and done < self.total):
            return
        rate = done / elapsed
        left = (self.total - done) / rate if rate > 0 else 0.0
        self.stream.write(f"\r{done:,}/{self.total:,} samples, {rate / 1e6:.2f} M/s, {left:.0f} s left ")
        self.stream.flush()
        self.drawn, self.shown = now, True

    def close(self):
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()
