"""navsim serve's Slurm campaign backend (issue 20 item 5) against a one-node Slurm that this test
starts (munged, slurmctld, slurmd on free ports, state in a temporary directory): a campaign above
max_runs goes through sbatch as `srun --mpi=pmix -n 2 navsim run ...`, is polled with scontrol,
and its results equal a local navsim run; a campaign is cancelled with scancel. Skipped (exit 77)
without root or without the Slurm and munge programs (Debian slurmctld, slurmd, slurm-client, munge).

usage: test_serve_slurm.py NAVSIM SOURCE_DIR"""

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_support import Server, check, finish, read  # noqa: E402

NAVSIM, SRC = sys.argv[1], sys.argv[2]
need = ["munged", "slurmctld", "slurmd", "sbatch", "scontrol", "scancel", "srun", "sinfo"]
missing = [p for p in need if not shutil.which(p, path="/usr/sbin:/usr/bin:/sbin:/bin")]
if missing or os.geteuid() != 0:
    print(f"SKIP: needs root and {', '.join(need)} (missing: {', '.join(missing) or 'root'})")
    sys.exit(77)


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    p = s.getsockname()[1]
    s.close()
    return p


root = tempfile.mkdtemp(prefix="navsim-slurm-")
for d in ("state", "spool", "log"):
    os.makedirs(os.path.join(root, d))
key = os.path.join(root, "munge.key")
with open(key, "wb") as f:
    f.write(os.urandom(1024))
os.chmod(key, 0o600)
sock = os.path.join(root, "munge.sock")
host = socket.gethostname().split(".")[0]
conf = os.path.join(root, "slurm.conf")
with open(conf, "w") as f:
    f.write(f"""ClusterName=navsimtest
SlurmctldHost={host}
AuthType=auth/munge
AuthInfo=socket={sock}
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
StateSaveLocation={root}/state
SlurmdSpoolDir={root}/spool
SlurmctldPidFile={root}/slurmctld.pid
SlurmdPidFile={root}/slurmd.pid
SlurmctldLogFile={root}/log/slurmctld.log
SlurmdLogFile={root}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
MinJobAge=600
NodeName={host} CPUs={os.cpu_count()} State=UNKNOWN
PartitionName=navsim Nodes={host} Default=YES MaxTime=INFINITE State=UP
""")
env = dict(os.environ, SLURM_CONF=conf)
os.environ["SLURM_CONF"] = conf  # the server passes it on to sbatch, scontrol, scancel
daemons = []


def pid_of(name):
    try:
        return int(read(os.path.join(root, name), "r").strip())
    except (OSError, ValueError):
        return None


def stop_daemons():
    """Stop the daemons this test started (by the pids they wrote) and wait until they are gone."""
    pids = [pid_of(n) for n in ("slurmd.pid", "slurmctld.pid", "munged.pid")]
    subprocess.run(["scontrol", "shutdown"], env=env, capture_output=True, timeout=30)
    for pid in pids:
        if pid:
            try:
                os.kill(pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
    t0 = time.time()
    while time.time() - t0 < 20 and any(p and os.path.exists(f"/proc/{p}") for p in pids):
        time.sleep(0.2)


try:
    subprocess.run(["munged", "-f", f"--socket={sock}", f"--key-file={key}", f"--log-file={root}/log/munged.log",
                    f"--pid-file={root}/munged.pid", f"--seed-file={root}/munged.seed"], check=True, timeout=30)
    subprocess.run(["slurmctld", "-f", conf], env=env, check=True, timeout=30)
    subprocess.run(["slurmd", "-f", conf], env=env, check=True, timeout=30)
    t0 = time.time()
    state = ""
    while time.time() - t0 < 60:
        state = subprocess.run(["sinfo", "-h", "-o", "%t"], env=env, capture_output=True, text=True).stdout.strip()
        if state == "idle":
            break
        time.sleep(0.5)
    if not check(state == "idle", f"the one-node Slurm comes up ({state!r})"):
        print(read(os.path.join(root, "log/slurmctld.log"), "r")[-2000:])
        raise SystemExit

    srv = Server(NAVSIM, {"slurm": 1, "max_runs": 2, "slurm_max_runs": 1000, "slurm_tasks": 2,
                          "slurm_time_min": 30, "job_threads": 1})
    print("server on", srv.host)
    scene_path = os.path.join(SRC, "scenes/car-figure-eight.yaml")
    st, _, j = srv.json("POST", "/api/runs?runs=4", read(scene_path))
    check(st == 202, f"a campaign above max_runs is accepted for Slurm ({st} {j})")
    rid = j["id"]
    j = srv.wait_run(rid, timeout=600)
    check(j and j.get("backend") == "slurm" and j["slurm_job"] > 0, f"it ran as a Slurm job ({j})")
    check(j and j["state"] == "done" and j["slurm_state"] == "COMPLETED", f"the campaign is done ({j})")
    script = read(os.path.join(srv.data, "jobs", rid, "campaign.sh"), "r")
    check("srun --mpi=pmix -n 2 " in script and "--runs 4" in script, f"the batch script ({script!r})")
    out = os.path.join(root, "local")
    subprocess.run([NAVSIM, "run", scene_path, "--runs", "4", "--threads", "1", "--quiet", "--kml", "--out", out],
                   check=True)
    st, _, served = srv.json("GET", f"/api/runs/{rid}/files/summary.json")
    local = json.loads(read(os.path.join(out, "summary.json")))
    for s in (served, local):
        s.pop("timing", None)
        s["scene"].pop("file", None)
    check(served == local, "summary.json equals the local run's (timing and scene path aside)")
    for name in ("truth.csv", "nav.csv", "errors.csv", "mc_stats.csv", "mc_final.csv", "gnss.csv"):
        st, _, body = srv.request("GET", f"/api/runs/{rid}/files/{name}")
        check(st == 200 and body == read(os.path.join(out, name)), f"{name} bit-identical to the local run")
    st, _, body = srv.request("GET", f"/api/runs/{rid}/files/results.zip")
    check(st == 200 and body[:2] == b"PK", "results.zip of the campaign")

    st, _, j = srv.json("POST", "/api/runs?runs=1001", read(scene_path))
    check(st == 422 and "slurm_max_runs" in j["errors"][0]["message"], f"above slurm_max_runs -> 422 ({st})")

    # Cancel a long campaign (urban-drive, 400 runs) once Slurm runs it.
    st, _, j = srv.json("POST", "/api/runs?runs=400", read(os.path.join(SRC, "scenes/urban-drive.yaml")))
    cid = j["id"]
    t0 = time.time()
    while time.time() - t0 < 120:
        j = srv.json("GET", f"/api/runs/{cid}")[2]
        if j.get("slurm_state") == "RUNNING":
            break
        time.sleep(0.3)
    check(j.get("slurm_state") == "RUNNING", f"the long campaign runs ({j})")
    st, _, _ = srv.json("DELETE", f"/api/runs/{cid}")
    check(st == 202, f"DELETE of a Slurm campaign -> 202 ({st})")
    j = srv.wait_run(cid, timeout=120)
    check(j and j["state"] == "cancelled" and j["slurm_state"] == "CANCELLED", f"scancel ended it ({j})")
    sc = subprocess.run(["scontrol", "show", "job", "-o", str(j["slurm_job"])], env=env, capture_output=True,
                        text=True).stdout
    check("JobState=CANCELLED" in sc, "Slurm reports it cancelled")
    check(srv.stop() == 0, "clean stop")
finally:
    stop_daemons()
if not check.__globals__["FAILS"]:
    shutil.rmtree(root, ignore_errors=True)
finish("test_serve_slurm")
