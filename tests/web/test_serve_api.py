"""navsim serve API contract (issue 20): every endpoint and every error answer
(400/403/404/405/409/413/415/422/429), the headers of every answer, a run end to end (events,
files, zip), cancellation, the estimate, and a clean stop on SIGTERM with a job running.

usage: test_serve_api.py NAVSIM SOURCE_DIR"""

import io
import json
import os
import subprocess
import sys
import time
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_support import Server, check, finish, read  # noqa: E402

NAVSIM, SRC = sys.argv[1], sys.argv[2]
SCENES = os.path.join(SRC, "scenes")
MINIMAL = read(os.path.join(SRC, "tests/data/scenes/valid-minimal.yaml"))
URBAN = read(os.path.join(SCENES, "urban-drive.yaml"))
CSP = "default-src 'self'; frame-ancestors 'none'"

# ---------------------------------------------------------------- options and configuration
r = subprocess.run([NAVSIM, "serve", "--port", "abc"], capture_output=True, text=True, timeout=30)
check(r.returncode == 2 and "--port" in r.stderr, f"--port abc -> exit 2 ({r.returncode} {r.stderr!r})")
r = subprocess.run([NAVSIM, "serve", "--frobnicate"], capture_output=True, text=True, timeout=30)
check(r.returncode == 2, f"unknown option -> exit 2 ({r.returncode})")
r = subprocess.run([NAVSIM, "serve", "--bind", "localhost"], capture_output=True, text=True, timeout=30)
check(r.returncode == 2 and "numeric" in r.stderr, f"--bind of a name -> exit 2 ({r.returncode})")
r = subprocess.run([NAVSIM, "serve", "--help"], capture_output=True, text=True, timeout=30)
check(r.returncode == 0 and r.stdout.startswith("usage: navsim serve"), "navsim serve --help")
check("  serve " in subprocess.run([NAVSIM, "--help"], capture_output=True, text=True).stdout, "navsim --help lists serve")
import tempfile  # noqa: E402
with tempfile.NamedTemporaryFile("w", suffix=".conf", delete=False) as f:
    f.write("# comment\njob_cpu_s = 60\nmax_runz = 3\nmax_runs = -1\nport 80\n")
r = subprocess.run([NAVSIM, "serve", "--config", f.name, "--port", "0"], capture_output=True, text=True, timeout=30)
os.unlink(f.name)
check(r.returncode == 2 and f"{f.name}:3: error: unknown key \"max_runz\"" in r.stderr and f"{f.name}:4: error: max_runs"
      in r.stderr and f"{f.name}:5: error: expected" in r.stderr, f"bad configuration -> exit 2 with FILE:LINE ({r.stderr!r})")

srv = Server(NAVSIM, {
    "max_body_bytes": 262144,
    "max_jobs_per_client": 3,
    "max_parallel_jobs": 1,
    "max_queued_jobs": 8,
    "max_runs": 500,
    "retry_after_s": 7,
    "estimate_cpu_s": 120,  # the sanitizer build is 10-20 times slower
})
print("server on", srv.host)


def headers_ok(hd, what):
    check(hd.get("content-security-policy") == CSP, f"{what}: CSP header {hd.get('content-security-policy')!r}")
    check(hd.get("x-content-type-options") == "nosniff", f"{what}: nosniff")
    check("access-control-allow-origin" not in hd, f"{what}: no CORS header")


# ---------------------------------------------------------------- static files (fixed list)
st, hd, body = srv.request("GET", "/")
check(st == 200 and b"test studio" in body, f"GET / -> index.html ({st})")
check(hd.get("content-type", "").startswith("text/html"), "GET / content type")
headers_ok(hd, "GET /")
st, hd, body = srv.request("GET", "/js/app.js")
check(st == 200 and hd.get("content-type", "").startswith("text/javascript"), f"GET /js/app.js ({st})")
for p in ["/secret.txt", "/passwd-link", "/etc/passwd", "/../secret.txt", "/js/../secret.txt", "/%2e%2e/secret.txt",
          "/index.html/", "//index.html", "/.hidden", "/manifest.txt", "/js", "/js/"]:
    st, hd, body = srv.request("GET", p)
    check(st == 404, f"GET {p} -> 404 (got {st})")
    check(b"root:" not in body and b"not listed" not in body, f"GET {p} leaks nothing")
st, hd, _ = srv.request("POST", "/", body=b"x")
check(st == 405 and "GET" in hd.get("allow", ""), f"POST / -> 405 with Allow ({st})")

# ---------------------------------------------------------------- catalogs
for kind in ("imu", "gnss"):
    st, hd, j = srv.json("GET", f"/api/catalog/{kind}")
    check(st == 200 and isinstance(j, list) and len(j) > 3, f"GET /api/catalog/{kind} ({st})")
    headers_ok(hd, f"catalog {kind}")
    out = subprocess.run([NAVSIM, "catalog", f"--{kind}", "--csv"], capture_output=True, text=True).stdout
    rows = len(out.strip().splitlines()) - 1
    check(len(j) == rows, f"{kind} catalog: {len(j)} entries, navsim catalog has {rows}")
    check(all("name" in e and "cost_class" in e for e in j), f"{kind} entries have name and cost_class")
st, _, imu = srv.json("GET", "/api/catalog/imu")
stim = [e for e in imu if "STIM300" in e["name"]]
check(len(stim) == 1 and stim[0]["grade"] and stim[0]["gyro"]["arw_deg_per_sqrt_h"] > 0,
      "IMU entries carry grade and datasheet-unit terms")
st, hd, _ = srv.request("DELETE", "/api/catalog/imu")
check(st == 405, f"DELETE /api/catalog/imu -> 405 ({st})")

# ---------------------------------------------------------------- schema
st, hd, schema = srv.json("GET", "/api/schema")
check(st == 200 and isinstance(schema, dict) and "$schema" in schema and "properties" in schema,
      f"GET /api/schema ({st})")

# ---------------------------------------------------------------- scene library
st, hd, lib = srv.json("GET", "/api/scenes")
names = [e["name"] for e in lib] if isinstance(lib, list) else []
check(st == 200 and "urban-drive" in names and "paper-parametric" in names, f"GET /api/scenes ({st}, {names})")
check("recorded-adis16465" not in names, "scenes naming files are not offered")
check(all(e.get("description") for e in lib), "every library scene has a description")
st, hd, body = srv.request("GET", "/api/scenes/urban-drive")
check(st == 200 and body == URBAN, f"GET /api/scenes/urban-drive is the file ({st})")
for p in ["/api/scenes/nope", "/api/scenes/..%2Furban-drive", "/api/scenes/../scenes/urban-drive",
          "/api/scenes/urban-drive.yaml", "/api/scenes/recorded-adis16465"]:
    st, _, _ = srv.request("GET", p)
    check(st == 404, f"GET {p} -> 404 ({st})")
st, _, _ = srv.request("GET", "/api/nothing")
check(st == 404, f"GET /api/nothing -> 404 ({st})")

# ---------------------------------------------------------------- validate
st, hd, j = srv.json("POST", "/api/validate", URBAN)
check(st == 200 and j == {"ok": True}, f"validate urban-drive -> 200 ok ({st} {j})")
headers_ok(hd, "validate")
st, _, j = srv.json("POST", "/api/validate", URBAN, {"Content-Type": "application/json"})
check(st == 200, f"validate with application/json ({st})")
st, _, j = srv.json("POST", "/api/validate", URBAN, {"Content-Type": "text/yaml; charset=utf-8"})
check(st == 200, f"validate with text/yaml; charset ({st})")
for bad in ["text/plain", "application/x-www-form-urlencoded", "multipart/form-data; boundary=x"]:
    st, _, j = srv.json("POST", "/api/validate", URBAN, {"Content-Type": bad})
    check(st == 415 and "error" in j, f"validate as {bad} -> 415 ({st})")
st, _, j = srv.json("POST", "/api/validate", URBAN, {"_no_type": True})
check(st == 415, f"validate without Content-Type -> 415 ({st})")
for f in ["invalid-many.yaml", "invalid-unknown-key.yaml", "invalid-syntax.yaml", "invalid-empty.yaml"]:
    path = os.path.join(SRC, "tests/data/scenes", f)
    st, _, j = srv.json("POST", "/api/validate", read(path))
    check(st == 422 and j and j.get("ok") is False and j.get("errors"), f"validate {f} -> 422 ({st})")
    cli = subprocess.run([NAVSIM, "check", path], capture_output=True, text=True).stderr
    for e in (j or {}).get("errors", []):
        loc = f":{e['line']}:{e['col']}: error: " if e["line"] > 0 else ": error: "
        text = loc + (f"{e['path']}: " if e["path"] else "") + e["message"]
        check(text in cli, f"{f}: API error {text!r} is navsim check's")
    check(len(j.get("errors", [])) == sum(1 for ln in cli.splitlines() if ": error: " in ln),
          f"{f}: as many errors as navsim check")
st, _, j = srv.json("POST", "/api/validate", b"format_version: 1\ntrajectory:\n  type: recorded\n  recorded: {file: /etc/passwd}\n")
check(st == 422 and j["errors"][0]["path"] == "trajectory.recorded.file" and "root:" not in json.dumps(j),
      f"a scene naming a file is refused without reading it ({st})")
st, _, j = srv.json("POST", "/api/validate", b"format_version: 1\ngnss:\n  constellation: {gps: almanac, almanac: /etc/shadow}\n")
check(st == 422 and j["errors"][0]["path"] == "gnss.constellation.almanac", f"almanac file refused ({st})")
st, hd, j = srv.json("GET", "/api/validate")
check(st == 405 and hd.get("allow") == "POST", f"GET /api/validate -> 405 Allow POST ({st} {hd.get('allow')})")

# ---------------------------------------------------------------- 413, 403, Host
big = b"# " + b"x" * 300000 + b"\nformat_version: 1\n"
st, _, j = srv.json("POST", "/api/validate", big)
check(st == 413 and "max_body_bytes" in j.get("error", ""), f"300 kB body -> 413 ({st})")
st, _, j = srv.json("POST", "/api/validate", URBAN, {"Origin": "http://evil.example"})
check(st == 403 and "cross-origin" in j.get("error", ""), f"cross-origin POST -> 403 ({st})")
st, _, j = srv.json("GET", "/api/scenes", None, {"Origin": "http://evil.example"})
check(st == 403, f"cross-origin GET -> 403 ({st})")
st, _, j = srv.json("POST", "/api/validate", URBAN, {"Origin": "null"})
check(st == 403, f"Origin null -> 403 ({st})")
st, _, j = srv.json("POST", "/api/validate", URBAN, {"Origin": f"http://{srv.host}"})
check(st == 200, f"same-origin POST -> 200 ({st})")
st, _, j = srv.json("GET", "/api/scenes", None, {"Host": "rebound.example:80"})
check(st == 403 and "Host" in j.get("error", ""), f"foreign Host (DNS rebinding) -> 403 ({st})")
st, _, j = srv.json("GET", "/api/scenes", None, {"Host": f"localhost:{srv.port}"})
check(st == 200, f"Host localhost:PORT -> 200 ({st})")

# ---------------------------------------------------------------- runs: 400 / 422 / 202
for q in ["abc", "0", "-3", "1.5", "", "9999999999999999999999"]:
    st, _, j = srv.json("POST", f"/api/runs?runs={q}", MINIMAL)
    check(st == 400 and "runs" in j.get("error", ""), f"runs={q!r} -> 400 ({st})")
st, _, j = srv.json("POST", "/api/runs?runs=501", MINIMAL)
check(st == 422 and j["errors"][0]["path"] == "simulation.runs", f"runs above max_runs -> 422 ({st})")
st, _, j = srv.json("POST", "/api/runs", read(os.path.join(SRC, "tests/data/scenes/invalid-many.yaml")))
check(st == 422 and len(j["errors"]) > 5, f"invalid scene run -> 422 ({st})")
long_scene = MINIMAL + b"trajectory: {type: parametric, duration_s: 100000}\nimu: {rate_hz: 1000}\n"
st, _, j = srv.json("POST", "/api/runs", long_scene)
check(st == 422 and "max_imu_samples" in j["errors"][0]["message"], f"duration x rate cap -> 422 ({st} {j})")
st, _, v = srv.json("POST", "/api/validate", long_scene)
check(st == 200 and v["ok"] is True and v["warnings"][0]["message"] == j["errors"][0]["message"],
      f"validate: valid, with the run limit as a warning ({st} {v})")

st, hd, j = srv.json("POST", "/api/runs?runs=3", read(os.path.join(SCENES, "car-figure-eight.yaml")))
check(st == 202 and len(j.get("id", "")) == 32 and j["state"] == "queued", f"POST /api/runs -> 202 ({st} {j})")
rid = j["id"]
check(hd.get("location") == f"/api/runs/{rid}", "202 carries Location")
# Events until the end of the run.
c = __import__("http.client").client.HTTPConnection("127.0.0.1", srv.port, timeout=300)
c.request("GET", f"/api/runs/{rid}/events")
r = c.getresponse()
check(r.status == 200 and r.getheader("Content-Type") == "text/event-stream", f"events stream ({r.status})")
states, progress = [], []
for raw in r:
    line = raw.decode().rstrip("\n")
    if line.startswith("data: {") and '"id"' in line:
        ev = json.loads(line[6:])
        states.append(ev["state"])
        progress.append(ev["progress"])
c.close()
check(states and states[-1] == "done", f"events end with done ({states[-3:]})")
check(progress == sorted(progress) and progress[-1] == 1.0, "progress never goes back and ends at 1")
check(any(0 < p < 1 for p in progress), f"intermediate progress reported ({progress})")
st, _, j = srv.json("GET", f"/api/runs/{rid}")
check(st == 200 and j["state"] == "done" and j["progress"] == 1 and j["runs"] == 3, f"GET run -> done ({j})")
check({"summary.json", "truth.csv", "nav.csv", "errors.csv", "mc_stats.csv", "gnss.csv", "tracks.kml",
       "scene.yaml", "results.zip"} <= set(j["files"]), f"files listed {j['files']}")
check("report.html" not in j["files"], "no report.html promised (the studio makes it in the browser)")
st, hd, body = srv.request("GET", f"/api/runs/{rid}/files/summary.json")
summ = json.loads(body)
check(st == 200 and summ["runs"] == 3 and summ["scene"]["name"] == "car-figure-eight", "summary.json")
st, hd, body = srv.request("GET", f"/api/runs/{rid}/files/truth.csv")
check(st == 200 and body.startswith(b"t_s") and "attachment" in hd.get("content-disposition", ""), "truth.csv")
st, hd, body = srv.request("GET", f"/api/runs/{rid}/files/scene.yaml")
check(st == 200 and body == read(os.path.join(SCENES, "car-figure-eight.yaml")), "scene.yaml is the posted scene")
st, hd, body = srv.request("GET", f"/api/runs/{rid}/files/results.zip")
z = zipfile.ZipFile(io.BytesIO(body))
check(st == 200 and z.testzip() is None and "summary.json" in z.namelist() and "scene.yaml" in z.namelist(),
      f"results.zip ({st}, {z.namelist()})")
check(json.loads(z.read("summary.json")) == summ, "zip's summary.json is the file")
for p in ["../scene.yaml", "..%2Fscene.yaml", "../../../../etc/passwd", "result", "nope.csv", "report.html",
          ".navsim-result", "summary.json/", "%00summary.json"]:
    st, _, body = srv.request("GET", f"/api/runs/{rid}/files/{p}")
    check(st in (400, 404) and b"root:" not in body, f"files/{p} -> 404 ({st})")
for p in ["zzz", rid.upper(), rid[:31], rid + "0", "../" + rid, rid[:31] + "g"]:
    st, _, j = srv.json("GET", f"/api/runs/{p}")
    check(st == 400, f"GET /api/runs/{p} -> 400 ({st})")
st, _, j = srv.json("GET", "/api/runs/" + "0" * 32)
check(st == 404, f"unknown run -> 404 ({st})")
st, _, j = srv.json("GET", f"/api/runs/{'0' * 32}/events")
check(st == 404, f"events of an unknown run -> 404 ({st})")
st, _, j = srv.json("DELETE", f"/api/runs/{rid}")
check(st == 409, f"DELETE of a finished run -> 409 ({st})")
st, hd, j = srv.json("PUT", f"/api/runs/{rid}", MINIMAL)
check(st == 405, f"PUT run -> 405 ({st})")
st, hd, j = srv.json("GET", "/api/runs")
check(st == 405, f"GET /api/runs -> 405 ({st})")

# ---------------------------------------------------------------- 429 per client, cancel, 409
ids = []
for i in range(3):
    st, _, j = srv.json("POST", "/api/runs?runs=100", URBAN)
    check(st == 202, f"long run {i} accepted ({st})")
    ids.append(j.get("id"))
st, hd, j = srv.json("POST", "/api/runs?runs=1", MINIMAL)
check(st == 429 and hd.get("retry-after") == "7" and "max_jobs_per_client" in j["error"],
      f"4th run of one client -> 429 Retry-After ({st} {hd.get('retry-after')})")
st, _, j = srv.json("GET", f"/api/runs/{ids[2]}")
check(j["state"] == "queued" and j["queue_position"] == 1, f"third run queued behind one ({j})")
st, _, j = srv.json("GET", f"/api/runs/{ids[2]}/files/summary.json")
check(st == 409, f"files of a queued run -> 409 ({st})")
running = srv.wait_run(ids[0], states=("running",), timeout=60)
check(running is not None, "first long run starts")
time.sleep(1.0)
for rid2 in ids:
    st, _, j = srv.json("DELETE", f"/api/runs/{rid2}")
    check(st == 202, f"DELETE a live run -> 202 ({st})")
for rid2 in ids:
    j = srv.wait_run(rid2, timeout=60)
    check(j and j["state"] == "cancelled", f"run {rid2[:6]} cancelled ({j and j['state']})")
    check(j and "summary.json" not in j["files"], "a cancelled run has no results")
check(not os.path.exists(os.path.join(srv.data, "jobs", ids[0], "result")), "a cancelled run leaves no result dir")
check(srv.job_processes() == [], "no job process is left after cancelling")

# ---------------------------------------------------------------- estimate
PARAMETRIC = read(os.path.join(SCENES, "paper-parametric.yaml"))
t0 = time.time()
st, _, j = srv.json("POST", "/api/estimate", PARAMETRIC)
dt = time.time() - t0
check(st == 200 and j and j.get("scene", {}).get("name") == "paper-parametric" and j.get("requirements"),
      f"estimate paper-parametric ({st})")
cli_dir = os.path.join(srv.root, "estimate-cli")
subprocess.run([NAVSIM, "estimate", os.path.join(SCENES, "paper-parametric.yaml"), "--out", cli_dir, "--quiet"],
               check=True)
cli = json.loads(read(os.path.join(cli_dir, "estimate.json")))
for k in ("analytic_final", "requirements"):
    check(j and j.get(k) == cli.get(k), f"estimate {k} equals navsim estimate's")
print(f"POST /api/estimate paper-parametric: {dt:.2f} s wall (machine load {os.getloadavg()[0]:.1f})")
# The answer is navsim estimate's estimate.json byte for byte (the scene saved as scene.yaml), also
# when it comes from the server's cache of answers by scene text; another text, another answer.
os.makedirs(os.path.join(srv.root, "estimate-same"), exist_ok=True)
with open(os.path.join(srv.root, "estimate-same", "scene.yaml"), "wb") as fh:
    fh.write(PARAMETRIC)
subprocess.run([NAVSIM, "estimate", "scene.yaml", "--out", "est", "--quiet"], check=True,
               cwd=os.path.join(srv.root, "estimate-same"))
same = read(os.path.join(srv.root, "estimate-same", "est", "estimate.json"))
for i in range(2):
    st, _, body = srv.request("POST", "/api/estimate", PARAMETRIC)
    check(st == 200 and body == same, f"estimate answer {i + 1} identical to navsim estimate's estimate.json")
renamed = PARAMETRIC.replace(b"name: paper-parametric", b"name: paper-parametric-2", 1)
check(renamed != PARAMETRIC, "the scene has a name to change")
st, _, j = srv.json("POST", "/api/estimate", renamed)
check(st == 200 and j and j.get("scene", {}).get("name") == "paper-parametric-2", f"a changed scene is estimated anew ({st})")
st, _, j = srv.json("POST", "/api/estimate", b"format_version: 1\nimu: {rate_hz: -1}\n")
check(st == 422 and j["errors"][0]["path"] == "imu.rate_hz", f"estimate of an invalid scene -> 422 ({st})")
st, _, j = srv.json("GET", "/api/estimate")
check(st == 405, f"GET /api/estimate -> 405 ({st})")
st, _, j = srv.json("GET", "/api/limits")
check(st == 200 and j["max_runs"] == 500 and "summary.json" in j["result_files"], f"GET /api/limits ({st})")
check("report.html" not in j["result_files"], f"no report.html among the result files ({j['result_files']})")

# ---------------------------------------------------------------- a second server on the same port
r = subprocess.run([NAVSIM, "serve", "--port", str(srv.port), "--data-dir", srv.data + "-2"], capture_output=True,
                   text=True, timeout=30)
check(r.returncode == 1 and "cannot listen" in r.stderr and "in use" in r.stderr, f"port in use -> exit 1 ({r.returncode} {r.stderr!r})")

# ---------------------------------------------------------------- SIGTERM with a job running
st, _, j = srv.json("POST", "/api/runs?runs=100", URBAN)
check(st == 202, "a run before the stop")
check(srv.wait_run(j["id"], states=("running",), timeout=60) is not None, "it runs")
time.sleep(0.5)
check(srv.job_processes() != [], "its process is there")
t0 = time.time()
rc = srv.stop()
check(rc == 0, f"SIGTERM -> exit 0 (got {rc})")
check(time.time() - t0 < 10, f"stopped in {time.time() - t0:.1f} s")
time.sleep(0.2)
check(srv.job_processes() == [], "no job process outlives the server")
# ---------------------------------------------------------------- IPv6
p6 = subprocess.Popen([NAVSIM, "serve", "--bind", "::1", "--port", "0", "--data-dir", srv.data + "-v6"],
                      stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
line = p6.stdout.readline()
check(line.startswith("listening on http://[::1]:"), f"--bind ::1 ({line!r})")
if line.startswith("listening on http://[::1]:"):
    port6 = int(line.strip().rstrip("/").rsplit(":", 1)[1])
    c6 = __import__("http.client").client.HTTPConnection("::1", port6, timeout=30)
    c6.request("GET", "/api/limits")
    r6 = c6.getresponse()
    check(r6.status == 200 and b"max_runs" in r6.read(), f"GET over IPv6 ({r6.status})")
    c6.close()
p6.send_signal(__import__("signal").SIGINT)
check(p6.wait(timeout=30) == 0, "SIGINT -> exit 0")

# ---------------------------------------------------------------- expiry by age, disk quota (503)
srv2 = Server(NAVSIM, {"result_max_age_s": 2})
st, _, j = srv2.json("POST", "/api/runs?runs=1", MINIMAL)
j = srv2.wait_run(j["id"])
check(j and j["state"] == "done", "a run to expire")
jobdir = os.path.join(srv2.data, "jobs", j["id"])
check(os.path.isdir(jobdir), "its directory exists")
t0 = time.time()
while time.time() - t0 < 30 and srv2.request("GET", f"/api/runs/{j['id']}")[0] == 200:
    time.sleep(0.2)
check(srv2.request("GET", f"/api/runs/{j['id']}")[0] == 404, f"expired after {time.time() - t0:.1f} s (age 2 s)")
t1 = time.time()
while time.time() - t1 < 10 and os.path.exists(jobdir):  # removed just after it leaves the list
    time.sleep(0.1)
check(not os.path.exists(jobdir), "its directory is removed")
check(srv2.stop() == 0, "clean stop of the expiry server")
srv3 = Server(NAVSIM, {"disk_quota_mb": 1})
st, hd, j = srv3.json("POST", "/api/runs?runs=1", MINIMAL)
check(st == 503 and hd.get("retry-after") and "disk_quota_mb" in j.get("error", ""), f"over the disk quota -> 503 ({st})")
check(srv3.stop() == 0, "clean stop of the quota server")
finish("test_serve_api")
