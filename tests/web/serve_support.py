"""Helpers of the navsim serve tests: start the real server on 127.0.0.1:0 with a configuration
and a small studio bundle made by the test, make raw HTTP requests, wait for runs.

Only the Python standard library is used (Debian python3)."""

import atexit
import http.client
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

FAILS = []


def check(cond, what):
    """Record a failed expectation (the test goes on, and fails at the end)."""
    if not cond:
        FAILS.append(what)
        print("FAIL:", what, flush=True)
    return cond


SERVERS = []


@atexit.register
def _no_server_left():
    """A test that stops on an exception must not leave its server running."""
    for s in SERVERS:
        if s.proc.poll() is None:
            s.proc.kill()
            s.proc.wait()


def finish(name):
    if not FAILS:  # keep everything of a failed test for a look
        for s in SERVERS:
            shutil.rmtree(s.root, ignore_errors=True)
    if FAILS:
        print(f"{name}: {len(FAILS)} failed expectation(s)")
        sys.exit(1)
    print(f"{name}: all expectations held")
    sys.exit(0)


def make_studio(root):
    """A studio bundle with a manifest; secret.txt exists but is not listed."""
    d = os.path.join(root, "studio")
    os.makedirs(os.path.join(d, "js"), exist_ok=True)
    with open(os.path.join(d, "index.html"), "w") as f:
        f.write("<!doctype html><title>test studio</title><script src=\"js/app.js\"></script>\n")
    with open(os.path.join(d, "js", "app.js"), "w") as f:
        f.write("console.log('studio');\n")
    with open(os.path.join(d, "secret.txt"), "w") as f:
        f.write("not listed\n")
    os.symlink("/etc/passwd", os.path.join(d, "passwd-link"))
    with open(os.path.join(d, "manifest.txt"), "w") as f:
        f.write("index.html\njs/app.js\n../secret.txt\n/etc/passwd\npasswd-link\n.hidden\n")
    return d


class Server:
    def __init__(self, navsim, config, root=None):
        self.root = root or tempfile.mkdtemp(prefix="navsim-serve-test-")
        self.data = os.path.join(self.root, "data")
        self.studio = make_studio(self.root) if not os.path.exists(os.path.join(self.root, "studio")) else \
            os.path.join(self.root, "studio")
        self.cfg = os.path.join(self.root, "serve.conf")
        with open(self.cfg, "w") as f:
            f.write("# navsim serve test configuration\n")
            for k, v in config.items():
                f.write(f"{k} = {v}\n")
        self.stderr = open(os.path.join(self.root, "server.log"), "w")
        self.proc = subprocess.Popen(
            [navsim, "serve", "--port", "0", "--data-dir", self.data, "--config", self.cfg, "--studio-dir",
             self.studio], stdout=subprocess.PIPE, stderr=self.stderr, text=True)
        line = self.proc.stdout.readline()
        m = re.fullmatch(r"listening on http://127\.0\.0\.1:(\d+)/\n", line)
        if not m:
            raise RuntimeError(f"unexpected first line {line!r}")
        self.port = int(m.group(1))
        SERVERS.append(self)
        self.host = f"127.0.0.1:{self.port}"

    def request(self, method, path, body=None, headers=None, timeout=900):
        """(status, headers dict (lower-case keys), body bytes)."""
        c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=timeout)
        h = dict(headers or {})
        if body is not None and "Content-Type" not in h and not h.get("_no_type"):
            h["Content-Type"] = "application/yaml"
        h.pop("_no_type", None)
        c.request(method, path, body=body, headers=h)
        r = c.getresponse()
        data = r.read()
        hd = {k.lower(): v for k, v in r.getheaders()}
        c.close()
        return r.status, hd, data

    def json(self, method, path, body=None, headers=None):
        st, hd, data = self.request(method, path, body, headers)
        try:
            j = json.loads(data) if data else None
        except ValueError:
            j = None
        return st, hd, j

    def raw(self, payload, read=True, timeout=10):
        """Send raw bytes on a new connection; the answer's status code (0 when none)."""
        s = socket.create_connection(("127.0.0.1", self.port), timeout=timeout)
        s.sendall(payload)
        if not read:
            return s
        data = b""
        try:
            while b"\r\n\r\n" not in data:
                chunk = s.recv(65536)
                if not chunk:
                    break
                data += chunk
        except (socket.timeout, ConnectionResetError):
            pass
        s.close()
        m = re.match(rb"HTTP/1\.[01] (\d{3})", data)
        return int(m.group(1)) if m else 0

    def wait_run(self, rid, states=("done", "failed", "cancelled"), timeout=600):
        t0 = time.time()
        while time.time() - t0 < timeout:
            st, _, j = self.json("GET", f"/api/runs/{rid}")
            if st != 200:
                return None
            if j["state"] in states:
                return j
            time.sleep(0.1)
        return None

    def rss_kib(self):
        vals = {}
        with open(f"/proc/{self.proc.pid}/status") as f:
            for line in f:
                k, _, v = line.partition(":")
                if k in ("VmRSS", "VmHWM", "Threads"):
                    vals[k] = int(v.split()[0])
        return vals

    def job_processes(self):
        """Processes whose working directory is inside this server's data directory."""
        found = []
        for p in os.listdir("/proc"):
            if not p.isdigit():
                continue
            try:
                cwd = os.readlink(f"/proc/{p}/cwd")
            except OSError:
                continue
            if cwd.startswith(self.data):
                found.append(int(p))
        return found

    def stop(self, sig=signal.SIGTERM):
        """Stop with @p sig (SIGTERM or SIGINT); the exit code (0 expected)."""
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            rc = self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            rc = self.proc.wait()
        self.stderr.close()
        return rc


def read(path, mode="rb"):
    with open(path, mode) as f:
        return f.read()
