"""navsim serve under load (issue 20 item 6): 50 clients at once on the loopback, each posting a
Monte Carlo run and following it over server-sent events, while others read the catalogs. Every
run completes (with its results) or is refused with 429 + Retry-After; the server's memory stays
bounded. The figures are printed.

usage: test_serve_load.py NAVSIM SOURCE_DIR"""

import http.client
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_support import Server, check, finish, read  # noqa: E402

NAVSIM, SRC = sys.argv[1], sys.argv[2]
SCENE = read(os.path.join(SRC, "scenes/car-figure-eight.yaml"))
CLIENTS = 50

srv = Server(NAVSIM, {
    "max_parallel_jobs": 2,
    "max_queued_jobs": 20,
    "max_jobs_per_client": 1000,  # all clients share 127.0.0.1 here
    "max_connections": 400,
    "max_connections_per_client": 400,
    "max_event_streams": 200,
    "max_event_streams_per_client": 200,
})
print("server on", srv.host)
out = {}
rss_samples = []
stop_sampling = threading.Event()


def sample():
    while not stop_sampling.is_set():
        try:
            rss_samples.append(srv.rss_kib()["VmRSS"])
        except OSError:
            pass
        time.sleep(0.2)


def client(i):
    rec = {"t0": time.time()}
    try:
        c = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=600)
        c.request("POST", "/api/runs?runs=2", body=SCENE, headers={"Content-Type": "application/yaml"})
        r = c.getresponse()
        body = r.read()
        rec["post"] = r.status
        rec["retry_after"] = r.getheader("Retry-After")
        if r.status == 202:
            rid = json.loads(body)["id"]
            rec["id"] = rid
            c.request("GET", f"/api/runs/{rid}/events")
            r = c.getresponse()
            last = None
            for raw in r:
                line = raw.decode()
                if line.startswith("data: {") and '"id"' in line:
                    last = json.loads(line[6:])
            rec["state"] = last["state"] if last else None
            c.close()
            c = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=600)
            c.request("GET", f"/api/runs/{rid}/files/summary.json")
            r = c.getresponse()
            s = r.read()
            rec["summary"] = r.status == 200 and json.loads(s)["runs"] == 2
        else:
            # A reader instead: the catalogs and the scene library.
            for p in ("/api/catalog/imu", "/api/catalog/gnss", "/api/scenes"):
                c.request("GET", p)
                r = c.getresponse()
                r.read()
                rec.setdefault("reads", []).append(r.status)
        c.close()
    except Exception as e:  # noqa: BLE001 - recorded and checked below
        rec["error"] = repr(e)
    rec["t1"] = time.time()
    out[i] = rec


sampler = threading.Thread(target=sample)
sampler.start()
t0 = time.time()
threads = [threading.Thread(target=client, args=(i,)) for i in range(CLIENTS)]
for t in threads:
    t.start()
for t in threads:
    t.join()
wall = time.time() - t0
stop_sampling.set()
sampler.join()

errors = [r["error"] for r in out.values() if "error" in r]
check(not errors, f"no client failed ({errors[:3]})")
posts = [r.get("post") for r in out.values()]
check(all(p in (202, 429) for p in posts), f"every POST answered 202 or 429 ({sorted(set(map(str, posts)))})")
ok = [r for r in out.values() if r.get("post") == 202]
refused = [r for r in out.values() if r.get("post") == 429]
check(all(r.get("retry_after") for r in refused), "every 429 carries Retry-After")
check(all(r.get("state") == "done" and r.get("summary") for r in ok), "every accepted run completed with its summary")
check(all(r.get("reads") == [200, 200, 200] for r in refused), "refused clients still read the catalogs")
check(len(ok) >= 22, f"the queue and the workers took at least 22 runs ({len(ok)})")
rss = srv.rss_kib()
peak = max(rss_samples) if rss_samples else 0
lat = sorted(r["t1"] - r["t0"] for r in ok)
print(f"load: {CLIENTS} clients, {len(ok)} runs completed, {len(refused)} refused with 429, wall {wall:.1f} s; "
      f"completed-run latency median {lat[len(lat) // 2]:.1f} s, max {lat[-1]:.1f} s; server VmRSS peak sampled "
      f"{peak} KiB, VmHWM {rss['VmHWM']} KiB, threads after {rss['Threads']}; load average {os.getloadavg()[0]:.1f}")
check(rss["VmHWM"] < 150 * 1024, f"server memory bounded (VmHWM {rss['VmHWM']} KiB < 150 MiB)")
st, _, j = srv.json("GET", "/api/scenes")
check(st == 200, "the server answers after the load")
check(srv.stop() == 0, "clean stop")
finish("test_serve_load")
