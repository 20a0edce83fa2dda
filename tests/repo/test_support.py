"""The bounded waits of the test support: a child that hangs, or leaves a
grandchild holding its output, ends the wait within its bound with a
message saying what was waited for; a remoting server that dies, never
listens, or finds its port taken is reported with what it printed."""

import os
import socket
import stat
import time

import pytest

from support.process import Timeout, run
from support.wine import PORT, RemotingServer, port_lock


def test_a_hanging_child_and_its_grandchild_are_stopped_at_the_bound(tmp_path):
    marker = tmp_path / "grandchild.pid"
    with pytest.raises(Timeout, match="waiting for sleepers: no end within 1 s"):
        # the grandchild inherits stdout: subprocess.run would wait for it
        run(
            ["sh", "-c", f"sleep 300 & echo $! > {marker}; echo started; wait"], timeout=1, what="waiting for sleepers"
        )  # only the bound raises Timeout: the sleeper would end with status 0
    grandchild = int(marker.read_text())
    deadline = time.monotonic() + 30  # SIGKILL was sent; a loaded machine may take a moment to end it
    while not gone(grandchild):
        assert time.monotonic() < deadline, f"the grandchild {grandchild} still runs 30 s after the bound"
        time.sleep(0.05)


def gone(pid):
    """pid has ended (no such process, or a zombie)."""
    try:
        with open(f"/proc/{pid}/stat") as stat_file:
            return stat_file.read().split(")")[1].split()[0] == "Z"
    except FileNotFoundError:
        return True


def test_output_and_exit_status_of_a_child_that_ends():
    done = run(["sh", "-c", "echo out; echo err >&2; exit 3"], timeout=30, what="sh")
    assert (done.returncode, done.stdout, done.stderr) == (3, "out\n", "err\n")
    with pytest.raises(AssertionError, match="sh: exit status 3"):
        run(["sh", "-c", "exit 3"], timeout=30, what="sh", check=True)


def fake_wine(folder, server_script):
    """A wine64 that runs server_script instead of the server, and a
    wineserver that does nothing."""
    folder.mkdir()
    for name, body in (("wine64", server_script), ("wineserver", "exit 0")):
        path = folder / name
        path.write_text(f"#!/bin/sh\n{body}\n")
        path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return folder


def server(tmp_path, script, seconds=60):
    wine_dir = fake_wine(tmp_path / "wine", script)
    prefix = tmp_path / "prefix"
    prefix.mkdir()
    env = dict(os.environ, WINEPREFIX=str(prefix))
    return RemotingServer(env, str(wine_dir), "server_tcp.exe", "Model.dll", tmp_path / "server.log", seconds)


def test_a_server_that_dies_at_start_is_reported_with_what_it_printed(tmp_path):
    # a start bound longer than the tests' backstop: only noticing the exit ends the wait
    with pytest.raises(AssertionError, match="(?s)attempt 1: .*exited with status 7 .*wine: could not load"):
        with server(tmp_path, "echo 'wine: could not load Model.dll'; exit 7", seconds=3600):
            pass


def test_a_server_that_never_listens_is_reported_at_the_bound(tmp_path):
    # only the bound raises Timeout's message: the sleeper would end with status 0
    with pytest.raises(AssertionError, match="(?s)did not listen on port 8080 within 1 s.*still starting"):
        with server(tmp_path, "echo 'still starting'; sleep 300", seconds=1):
            pass


def test_a_port_taken_by_another_process_is_refused(tmp_path):
    never_started = server(tmp_path, "sleep 300")
    with port_lock(), socket.socket() as taken:  # no Windows test uses the port meanwhile
        taken.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            taken.bind(("127.0.0.1", PORT))
        except OSError:
            pytest.fail(f"port {PORT} is taken on this machine by another program: the Windows test cannot run either")
        taken.listen()
        with pytest.raises(AssertionError, match=f"port {PORT} .* is already listened on by .*python"):
            never_started.start()
