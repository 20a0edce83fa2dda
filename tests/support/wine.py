"""Windows binaries under wine through fmpy's remoting, every wait bounded.

fmpy's remoting client (binaries/linux64/<model>.so) normally starts the
server itself, `wine64 server_tcp.exe <model>.dll <lock file>`, and the
server stops once it can open that lock file for writing: the client's
POSIX read lock on it is meant to prevent that, but wine does not see a
lock taken by a Linux process, and as root the file's mode 0000 does not
stop it either. So the server quits about 0.5 s after it starts, and a run
that takes longer (any run on a busy machine, or 400 steps on an idle one)
loses its server mid-call; the client (rpclib, no call timeout) then waits
for an answer for ever.

Here the server is started by us, without a lock file (the client's
"started externally" mode, chosen by naming the client client_tcp): it
lives until we stop it, its start is awaited with a bound (the port must be
listened on by it or its wineserver), and what wine printed is in every
failure.
The server's port is fixed (rpclib's 8080) and machine-wide, so the runs of
every test process on the machine are serialised by one lock file
(port_lock) and the port must be free before a start."""

import contextlib
import fcntl
import os
import re
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

from fmpy.util import add_remoting

from support.process import Timeout, kill_session, run, tail

PORT = 8080  # rpc::constants::DEFAULT_PORT in fmpy's server and client
START_SECONDS = 60  # wine's start on a busy machine, measured at 1 to 15 s
ATTEMPTS = 2
CLIENT = "client_tcp"  # fmpy's client in "server started externally" mode


@contextlib.contextmanager
def port_lock():
    """The machine-wide lock on PORT, held while a server runs or a test
    uses the port (a sanitizer tree's tests run beside the release tree's)."""
    with open(Path(tempfile.gettempdir()) / f"fmpy-remoting-port-{PORT}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


def environment(wine_dir, prefix):
    return dict(os.environ, PATH=f"{wine_dir}:{os.environ['PATH']}", WINEPREFIX=str(prefix), WINEDEBUG="-all")


def stop_wineserver(env, wine_dir):
    """Stop the wineserver of env's prefix and wait until it has gone (a
    wine started while the old server is still exiting dies on arrival)."""
    wineserver = str(Path(wine_dir) / "wineserver")
    run([wineserver, "--kill"], timeout=60, what="wineserver --kill", env=env)
    run([wineserver, "--wait"], timeout=60, what="wineserver --wait (the old wineserver to exit)", env=env)


def make_prefix(env, wine_dir):
    run(
        [str(Path(wine_dir) / "wine64"), "wineboot", "--init"],
        timeout=300,
        what="wineboot --init (the wine prefix)",
        env=env,
        check=True,
    )
    stop_wineserver(env, wine_dir)


def listeners(port):
    """{socket inode: local address} of TCP sockets listening on port."""
    found = {}
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with contextlib.suppress(OSError):
            for line in Path(table).read_text().splitlines()[1:]:
                fields = line.split()
                local, state, inode = fields[1], fields[3], fields[9]
                if state == "0A" and int(local.rsplit(":", 1)[1], 16) == port:
                    found[inode] = local
    return found


def owners(inodes):
    """{pid: command line} of the processes holding these sockets."""
    wanted = {f"socket:[{i}]" for i in inodes}
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        with contextlib.suppress(OSError):
            for fd in (entry / "fd").iterdir():
                with contextlib.suppress(OSError):
                    if os.readlink(fd) in wanted:
                        found[int(entry.name)] = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode().strip()
    return found


def session_of(pid):
    with contextlib.suppress(OSError, ValueError):
        stat = Path(f"/proc/{pid}/stat").read_text()
        return int(stat.rsplit(")", 1)[1].split()[3])  # field 6: session id
    return None


def remoting_copy(fmu_dir, target):
    """The extracted FMU at fmu_dir as a win64-only FMU at target, with
    fmpy's client as client_tcp (it then connects to a running server
    rather than starting one). Returns the path of the DLL to serve."""
    shutil.copytree(fmu_dir, target)
    shutil.rmtree(target / "binaries" / "linux64", ignore_errors=True)
    description = target / "modelDescription.xml"
    identifier = re.search(r'modelIdentifier="([^"]+)"', description.read_text()).group(1)
    add_remoting(str(target), host_platform="linux64", remote_platform="win64")
    (target / "binaries" / "linux64" / f"{identifier}.so").rename(target / "binaries" / "linux64" / f"{CLIENT}.so")
    description.write_text(
        description.read_text().replace(f'modelIdentifier="{identifier}"', f'modelIdentifier="{CLIENT}"')
    )
    return target / "binaries" / "win64" / f"{identifier}.dll"


class RemotingServer:
    """fmpy's server_tcp.exe under wine serving one DLL, up and listening
    on PORT while the with-block runs; stopped (with its wineserver) after."""

    def __init__(self, env, wine_dir, server_exe, dll, log, start_seconds=START_SECONDS):
        self.env, self.wine_dir, self.server_exe, self.dll, self.log = env, wine_dir, server_exe, dll, Path(log)
        self.start_seconds = start_seconds
        self.process = None
        self._lock = None

    def output(self):
        return tail(self.log.read_text(errors="replace")) if self.log.exists() else "(nothing)"

    def _start_once(self):
        busy = owners(listeners(PORT))
        if listeners(PORT):
            raise AssertionError(
                f"port {PORT} (fmpy's remoting port) is already listened on by {busy or 'an unknown process'}; "
                "a client would talk to that server instead of ours"
            )
        with open(self.log, "ab") as log:
            self.process = subprocess.Popen(
                [str(Path(self.wine_dir) / "wine64"), str(self.server_exe), str(self.dll)],
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                env=self.env,
                start_new_session=True,
            )
        deadline = time.monotonic() + self.start_seconds
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise AssertionError(
                    f"the remoting server under wine exited with status {self.process.returncode} "
                    f"before it listened on port {PORT}; it printed:\n{self.output()}"
                )
            # wine keeps a process's sockets in its wineserver
            holders = owners(listeners(PORT))
            if any(session_of(pid) == self.process.pid or "wineserver" in command for pid, command in holders.items()):
                return
            time.sleep(0.1)
        raise Timeout(
            f"the remoting server under wine did not listen on port {PORT} within {self.start_seconds} s; "
            f"it printed:\n{self.output()}"
        )

    def stop(self):
        if self.process is not None:
            kill_session(self.process)
            self.process = None
        stop_wineserver(self.env, self.wine_dir)

    def start(self):
        """Start the server (ATTEMPTS tries); the caller holds port_lock."""
        failures = []
        for attempt in range(ATTEMPTS):
            stop_wineserver(self.env, self.wine_dir)
            try:
                self._start_once()
                return self
            except AssertionError as failure:
                failures.append(f"attempt {attempt + 1}: {failure}")
                self.stop()
        raise AssertionError("\n".join(failures))

    def __enter__(self):
        self._lock = port_lock()
        self._lock.__enter__()
        try:
            return self.start()
        except BaseException:
            self._lock.__exit__(None, None, None)
            raise

    def __exit__(self, *exc):
        try:
            self.stop()
        finally:
            self._lock.__exit__(None, None, None)
