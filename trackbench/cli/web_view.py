"""`trackbench view ... --web`: a recording served to a browser by rerun's web viewer, on one
port, so that one ssh port-forward reaches it from another machine.

One HTTP server of ours listens on BIND:PORT (localhost by default). It serves the .rrd file
itself at /<file name> and passes every other request to rerun's own web viewer (the page,
its JavaScript and WebAssembly), which a `rerun --serve-web` child serves on a free port of
127.0.0.1. The page at / loads the file (`?url=`): the viewer replays it with the layout
(blueprint) the recording holds. No gRPC server runs: the browser downloads the file once.

The child runs in its own process group (a Ctrl-C in the terminal reaches only us) and is
told to stop when we end (Linux: the parent-death signal), and its group is ended on every
way out: Ctrl-C, SIGTERM, SIGHUP (the ssh session closed) or an error.
"""

import errno
import http.client
import http.server
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from urllib.parse import quote, urlsplit

DEFAULT_PORT = 9090
LOCALHOST = "127.0.0.1"
VIEWER_START = 30.0   # s: how long rerun's web viewer may take to listen


class WebViewError(RuntimeError):
    """The web viewer cannot start; the message (one line) says why."""


def rerun_binary():
    """The rerun executable that rerun-sdk ships (run directly, not through its Python wrapper,
    which would stand between us and it as another process)."""
    try:
        import rerun_cli
    except ImportError:
        return None
    exe = Path(rerun_cli.__file__).parent / ("rerun.exe" if sys.platform.startswith("win") else "rerun")
    return exe if exe.is_file() else None


def _die_with_parent():
    """In the child before exec: a new session (no terminal signals), and SIGTERM when the
    process that started it dies (Linux), so that even a killed `trackbench view` leaves
    nothing behind."""
    os.setsid()
    if sys.platform.startswith("linux"):
        import ctypes
        try:
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)   # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass


def _free_port():
    with socket.socket() as s:
        s.bind((LOCALHOST, 0))
        return s.getsockname()[1]


def _etag():
    from importlib.metadata import PackageNotFoundError, version
    try:
        return f'"rerun-{version("rerun-sdk")}"'
    except PackageNotFoundError:
        return '"rerun"'


class _Server(http.server.ThreadingHTTPServer):
    daemon_threads = True
    allow_reuse_address = True

    def __init__(self, address, rrd):
        self.rrd = Path(rrd)
        self.rrd_path = "/" + quote(self.rrd.name)
        self.viewer_port = None
        self.viewer = None       # the rerun child, once started
        self.cache = {}          # path -> (status, content type, body): the viewer's files
        self.lock = threading.Lock()
        super().__init__(address, _Handler)

    def handle_error(self, request, client_address):
        """A browser that closes the page mid-download is no error worth a traceback."""
        if not isinstance(sys.exc_info()[1], (ConnectionError, TimeoutError)):
            super().handle_error(request, client_address)


class _Handler(http.server.BaseHTTPRequestHandler):
    server: _Server
    protocol_version = "HTTP/1.1"

    def log_message(self, format, *args):   # noqa: A002 - the base class's signature
        pass

    def do_GET(self):
        parts = urlsplit(self.path)
        if parts.path == self.server.rrd_path:
            return self._send_recording()
        if parts.path in ("/", "/index.html") and not parts.query:
            host = self.headers.get("Host") or f"localhost:{self.server.server_address[1]}"
            url = quote(f"http://{host}{self.server.rrd_path}", safe="")
            return self._reply(302, "text/plain", b"", {"Location": f"/?url={url}"})
        return self._proxy(parts.path, self.path)

    def _reply(self, status, ctype, body, headers=None):
        self.send_response(status)
        if status != 304:     # "not modified" has no body, nor its length
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(body)))
        for k, v in ({"Cache-Control": "no-store"} | (headers or {})).items():
            self.send_header(k, v)
        self.end_headers()
        self.wfile.write(body)

    def _send_recording(self):
        rrd = self.server.rrd
        try:
            f = open(rrd, "rb")
        except OSError as e:
            return self._reply(404, "text/plain", f"{rrd}: {e.strerror}".encode())
        with f:
            self.send_response(200)
            self.send_header("Content-Type", "application/octet-stream")
            self.send_header("Content-Length", str(os.fstat(f.fileno()).st_size))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            while chunk := f.read(1 << 20):
                self.wfile.write(chunk)

    def _proxy(self, key, target):
        """The viewer's own files from rerun's server, kept once fetched (they never change
        while it runs; the WebAssembly is ~40 MB), and tagged with rerun's version: a browser
        that has them asks again (a reload) and gets 304, not 40 MB more through the tunnel."""
        tag = {"Cache-Control": "no-cache", "ETag": _etag()}
        if key == target and self.headers.get("If-None-Match") == tag["ETag"] and key in self.server.cache:
            return self._reply(304, self.server.cache[key][1], b"", tag)
        hit = self.server.cache.get(key) if key == target else None
        if hit is None:
            conn = http.client.HTTPConnection(LOCALHOST, self.server.viewer_port, timeout=60)
            try:
                conn.request("GET", target)
                resp = conn.getresponse()
                hit = (resp.status, resp.getheader("Content-Type") or "application/octet-stream", resp.read())
            except OSError as e:
                return self._reply(502, "text/plain", f"rerun's web viewer did not answer: {e}".encode())
            finally:
                conn.close()
            if hit[0] == 200 and key == target:
                with self.server.lock:
                    self.server.cache[key] = hit
        self._reply(*hit, tag if hit[0] == 200 else None)


def listen(port, bind, rrd):
    """Our server bound to BIND:PORT (not serving yet); WebViewError when it cannot be."""
    try:
        return _Server((bind, port), rrd)
    except OverflowError:
        raise WebViewError(f"--port {port}: expected a port number from 1 to 65535") from None
    except OSError as e:
        if e.errno == errno.EADDRINUSE:
            why = f"port {port} is in use on {bind} (another viewer?): choose another with --port"
        elif e.errno == errno.EACCES:
            why = f"port {port} needs privileges on {bind}: choose one above 1023 with --port"
        elif e.errno in (errno.EADDRNOTAVAIL, socket.EAI_NONAME) or isinstance(e, socket.gaierror):
            why = f"--bind {bind}: not an address of this machine"
        else:
            why = f"cannot listen on {bind}:{port}: {e.strerror or e}"
        raise WebViewError(why) from None


def start_viewer(server, log):
    """rerun's web viewer on a free port of 127.0.0.1, in its own process group (server.viewer:
    the caller ends it); returns once it listens. WebViewError when it cannot start."""
    exe = rerun_binary()
    cmd = [str(exe)] if exe else [sys.executable, "-m", "rerun"]
    port = _free_port()
    url = f"http://{LOCALHOST}:{server.server_address[1]}{server.rrd_path}"
    cmd += [url, "--serve-web", "--bind", LOCALHOST, "--web-viewer-port", str(port)]
    try:
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                preexec_fn=_die_with_parent if os.name == "posix" else None)
    except OSError as e:
        raise WebViewError(f"could not start rerun's web viewer ({e})") from None
    server.viewer, server.viewer_port = proc, port
    deadline = time.monotonic() + VIEWER_START
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            log.seek(0)
            tail = " ".join(log.read().decode(errors="replace").split()[-40:])
            raise WebViewError(f"rerun's web viewer stopped at start (exit {proc.returncode}): {tail}")
        try:
            socket.create_connection((LOCALHOST, port), timeout=0.5).close()
            return
        except OSError:
            time.sleep(0.1)
    raise WebViewError(f"rerun's web viewer did not listen within {VIEWER_START:g} s")


def stop_group(proc):
    """End the child's process group: SIGTERM, then SIGKILL after 3 s (not once the child has
    ended and been waited for: its id may then be another's)."""
    if proc is None or proc.poll() is not None:
        return
    for sig, wait in ((signal.SIGTERM, 3.0), (signal.SIGKILL, 3.0)):
        try:
            os.killpg(proc.pid, sig)
        except (ProcessLookupError, PermissionError):
            pass
        try:
            proc.wait(wait)
            return
        except subprocess.TimeoutExpired:
            continue


def addresses(port, bind):
    """The lines a user reads: the address to open here, the ssh port-forward from elsewhere."""
    import getpass
    host = socket.gethostname()
    here = "localhost" if bind in (LOCALHOST, "localhost", "::1", "0.0.0.0", "::") else bind
    lines = [f"on this machine:     open http://{here}:{port}"]
    if here == "localhost":
        lines += [f"from your own:       ssh -N -L {port}:localhost:{port} {getpass.getuser()}@{host}"
                  f"   then open http://localhost:{port}",
                  "                     (through a login node: add -J USER@LOGIN_NODE to that ssh)"]
    if bind in ("0.0.0.0", "::"):
        lines.append(f"from this network:   open http://{host}:{port}")
    return lines


def _interrupting(signum, frame):
    raise KeyboardInterrupt


def serve(rrd, port=DEFAULT_PORT, bind=LOCALHOST, echo=print):
    """Serve the recording ``rrd`` to browsers until Ctrl-C, SIGTERM or SIGHUP; returns 0.
    WebViewError (one line) when it cannot start. ``port`` 0 takes a free one."""
    server = listen(port, bind, rrd)
    old = {s: signal.getsignal(s) for s in (signal.SIGTERM, getattr(signal, "SIGHUP", None)) if s}
    try:
        for s in old:
            signal.signal(s, _interrupting)
        with tempfile.TemporaryFile() as log:
            start_viewer(server, log)
            echo(f"serving {rrd} with rerun's web viewer")
            for line in addresses(server.server_address[1], bind):
                echo("  " + line)
            echo("Ctrl-C stops it")
            server.serve_forever(poll_interval=0.25)
    except KeyboardInterrupt:
        pass
    finally:
        stop_group(server.viewer)
        server.server_close()
        for s, h in old.items():
            signal.signal(s, h)
    try:
        echo("stopped")
    except OSError:     # the terminal went away (SIGHUP): nothing to tell
        pass
    return 0
