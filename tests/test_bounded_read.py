"""mechbook.app.bounded under an interrupt: a Ctrl-C that arrives inside `os.fdopen`, after
the new file object has taken (and, collected, closed) the descriptor, must stay a
KeyboardInterrupt. Before the fix, closing the descriptor again raised OSError (EBADF),
which escaped `mechbook watch`'s Ctrl-C handler: a traceback and exit status 1 instead of
"stopped watching" (seen in make test)."""

from __future__ import annotations

import os

import pytest

from mechbook.app import bounded


def test_an_interrupt_inside_fdopen_stays_an_interrupt(tmp_path, monkeypatch):
    path = tmp_path / "a.yaml"
    path.write_text("x: 1\n", "utf-8")
    real = os.fdopen

    def interrupted(fd, *args, **kwargs):
        real(fd, *args, **kwargs).close()  # the descriptor is taken and already closed
        raise KeyboardInterrupt

    monkeypatch.setattr(bounded.os, "fdopen", interrupted)
    with pytest.raises(KeyboardInterrupt):
        bounded.read_regular(path, 1000)


def test_the_descriptor_is_closed_when_the_file_is_refused(tmp_path):
    path = tmp_path / "big.yaml"
    path.write_bytes(b"x" * 2000)
    before = len(os.listdir("/proc/self/fd"))
    for _ in range(50):
        with pytest.raises(bounded.Unreadable):
            bounded.read_regular(path, 1000)
    assert len(os.listdir("/proc/self/fd")) <= before
