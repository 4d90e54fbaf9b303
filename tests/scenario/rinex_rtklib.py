#!/usr/bin/env python3
"""issue 22: navsim run --export rinex, then RTKLIB's rnx2rtkp single-point positions from the
exported files, compared epoch by epoch with our own least-squares PVT (rinex/pvt.csv) and with
the reference antenna position (within DOP x sigma). Exit 77 (ctest SKIP) without rnx2rtkp.

usage: rinex_rtklib.py NAVSIM WORKDIR [--ideal] [--max-cm X] [--weights-differ] SCENE... ; options apply to the
scenes after them; prints the figures it measured."""
import math
import os
import shutil
import subprocess
import sys

# rnx2rtkp options (docs/rinex.md): single point, L1, no ionosphere or troposphere model (the
# simulation has neither), no elevation mask (the simulation's mask already chose the satellites),
# GPS + GLONASS, ECEF output in GPS time. stats-errphase makes RTKLIB's code variance
# (100 x errphase)^2 so large that its other, satellite-dependent variance terms (ephemeris URA,
# the GLONASS factor) no longer matter: equal weights, as our unweighted least squares.
CONF = """pos1-posmode       =single
pos1-frequency     =l1
pos1-soltype       =forward
pos1-elmask        =0
pos1-snrmask_r     =off
pos1-ionoopt       =off
pos1-tropopt       =off
pos1-sateph        =brdc
pos1-navsys        =5
pos2-armode        =off
stats-eratio1      =100
stats-errphase     =100
stats-errphaseel   =0
out-solformat      =xyz
out-timesys        =gpst
out-timeform       =tow
out-timendec       =3
out-outhead        =on
"""

WGS84_A = 6378137.0
WGS84_F = 1.0 / 298.257223563


def lat_lon(x, y, z):
    """Geodetic latitude and longitude [rad] of an ECEF point (Bowring's iteration)."""
    e2 = WGS84_F * (2.0 - WGS84_F)
    p = math.hypot(x, y)
    lat = math.atan2(z, p * (1.0 - e2))
    for _ in range(6):
        n = WGS84_A / math.sqrt(1.0 - e2 * math.sin(lat) ** 2)
        h = p / math.cos(lat) - n
        lat = math.atan2(z, p * (1.0 - e2 * n / (n + h)))
    return lat, math.atan2(y, x)


def to_ned(d, lat, lon):
    sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
    n = -sl * co * d[0] - sl * so * d[1] + cl * d[2]
    e = -so * d[0] + co * d[1]
    dn = -cl * co * d[0] - cl * so * d[1] - sl * d[2]
    return n, e, dn


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run_scene(navsim, work, scene, ideal, max_m, weights_differ):
    name = os.path.splitext(os.path.basename(scene))[0]
    out = os.path.join(work, name + ("-ideal" if ideal else ""))
    cmd = [navsim, "run", scene, "--runs", "1", "--export", "rinex", "--out", out, "--force", "-q"]
    if ideal:
        cmd.append("--ideal")
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        fail("%s exited %d: %s" % (" ".join(cmd), r.returncode, r.stderr))
    rdir = os.path.join(out, "rinex")
    obs = [f for f in os.listdir(rdir) if f.endswith(".obs")]
    nav = [f for f in os.listdir(rdir) if f.endswith(".nav")]
    if len(obs) != 1 or len(nav) != 1:
        fail("%s: expected one .obs and one .nav, found %s" % (rdir, sorted(os.listdir(rdir))))
    conf = os.path.join(out, "spp.conf")
    with open(conf, "w") as f:
        f.write(CONF)
    pos = os.path.join(out, "spp.pos")
    r = subprocess.run(["rnx2rtkp", "-k", conf, "-o", pos, os.path.join(rdir, obs[0]), os.path.join(rdir, nav[0])],
                       capture_output=True, text=True)
    if r.returncode != 0 or not os.path.exists(pos):
        fail("rnx2rtkp exited %d: %s" % (r.returncode, r.stderr[-500:]))
    rtk = {}
    with open(pos) as f:
        for line in f:
            if line.startswith("%") or not line.strip():
                continue
            v = line.split()
            # The solution time is the epoch minus the estimated receiver clock (microseconds).
            t = int(round(float(v[0]) * 604800.0 + float(v[1])))
            rtk[t] = (float(v[2]), float(v[3]), float(v[4]), int(v[5]))
    rows = []
    with open(os.path.join(rdir, "pvt.csv")) as f:
        head = f.readline().strip().split(",")
        for line in f:
            rows.append(dict(zip(head, (float(x) for x in line.split(",")))))
    if len(rows) < 50:
        fail("%s: only %d PVT epochs" % (scene, len(rows)))
    d2 = []
    dmax = 0.0
    z = []  # RTKLIB error / (DOP x sigma) per axis
    missing = 0
    for row in rows:
        t = int(round(row["t_gps_s"]))
        if t not in rtk or rtk[t][3] != 5:
            missing += 1
            continue
        x, y, zz, _ = rtk[t]
        d = math.sqrt((x - row["x_m"]) ** 2 + (y - row["y_m"]) ** 2 + (zz - row["z_m"]) ** 2)
        d2.append(d * d)
        dmax = max(dmax, d)
        lat, lon = lat_lon(row["ref_x_m"], row["ref_y_m"], row["ref_z_m"])
        ned = to_ned((x - row["ref_x_m"], y - row["ref_y_m"], zz - row["ref_z_m"]), lat, lon)
        for k, sd in enumerate(("sd_n_m", "sd_e_m", "sd_d_m")):
            z.append(abs(ned[k]) / row[sd])
    n = len(d2)
    rms = math.sqrt(sum(d2) / n) if n else float("nan")
    f1 = sum(1 for v in z if v <= 1.0) / len(z) if z else 0.0
    f3 = sum(1 for v in z if v <= 3.0) / len(z) if z else 0.0
    print("%s%s: %d PVT epochs, %d solved by rnx2rtkp; rnx2rtkp - our PVT: RMS %.2f cm, max %.2f cm; "
          "rnx2rtkp - reference within 1 x DOP x sigma: %.3f, within 3 x: %.4f (per axis, N/E/D pooled)"
          % (name, " (--ideal)" if ideal else "", len(rows), n, 100.0 * rms, 100.0 * dmax, f1, f3))
    if missing > 0.02 * len(rows):
        fail("%s: rnx2rtkp has no single solution at %d of our %d PVT epochs" % (scene, missing, len(rows)))
    # Centimetres: every epoch's 3-D difference below max_m (docs/rinex.md: GPS records
    # reproduce our orbits to micrometres, GLONASS records to centimetres).
    # With --weights-differ (GPS + GLONASS with noise) the two are different estimators: RTKLIB
    # scales the GLONASS code sigma by 1.5 (EFACT_GLO), our least squares weighs all alike.
    if not weights_differ and not dmax < max_m:
        fail("%s: rnx2rtkp and our PVT differ by up to %.4f m" % (scene, dmax))
    if not ideal:
        # Gaussian per-axis errors: 68.3 % within 1 sigma, 99.73 % within 3 sigma; the bands allow
        # the sampling spread of about 3 x N epochs (independent draws per epoch).
        if not (0.60 <= f1 <= 0.76):
            fail("%s: %.3f of the axis errors within DOP x sigma (expected about 0.683)" % (scene, f1))
        if not f3 >= 0.99:
            fail("%s: %.4f of the axis errors within 3 DOP x sigma (expected about 0.997)" % (scene, f3))


def contract(navsim, work, scene):
    """What needs no RTKLIB: refusals (exit 2, nothing written) and bit-identical files for any
    thread count."""
    bad = os.path.join(work, "no-constellation.yaml")
    with open(scene) as f:
        text = f.read()
    # The same scene without its gnss.constellation section.
    lines, skip = [], False
    for line in text.splitlines():
        if line.startswith("  constellation:"):
            skip = True
            continue
        if skip and (line.startswith("    ") or not line.strip()):
            continue
        skip = False
        lines.append(line)
    with open(bad, "w") as f:
        f.write("\n".join(lines) + "\n")
    out = os.path.join(work, "refused")
    r = subprocess.run([navsim, "run", bad, "--export", "rinex", "--out", out, "-q"], capture_output=True, text=True)
    if r.returncode != 2 or "gnss.constellation" not in r.stderr or os.path.exists(out):
        fail("scene without gnss.constellation: exit %d, stderr %r, %s written" % (r.returncode, r.stderr,
                                                                                   out if os.path.exists(out) else "nothing"))
    r = subprocess.run([navsim, "run", scene, "--export", "rinexx", "--out", out, "-q"], capture_output=True, text=True)
    if r.returncode != 2 or "expected kfgins or rinex" not in r.stderr or os.path.exists(out):
        fail("--export rinexx: exit %d, stderr %r" % (r.returncode, r.stderr))
    files = []
    for threads in ("1", "2"):
        d = os.path.join(work, "threads" + threads)
        r = subprocess.run([navsim, "run", scene, "--runs", "2", "--threads", threads, "--export", "rinex",
                            "--export", "kfgins", "--out", d, "--force", "-q"], capture_output=True, text=True)
        if r.returncode != 0:
            fail("navsim run --threads %s: exit %d: %s" % (threads, r.returncode, r.stderr))
        rd = os.path.join(d, "rinex")
        files.append({n: open(os.path.join(rd, n), "rb").read() for n in sorted(os.listdir(rd))})
        if not os.path.isdir(os.path.join(d, "kfgins")):
            fail("--export rinex --export kfgins: no kfgins/ in %s" % d)
    if files[0] != files[1] or len(files[0]) != 3:
        fail("rinex/ differs between 1 and 2 threads or lacks files: %s" % sorted(files[0]))
    print("contract: refusals exit 2 with nothing written; rinex/ bit-identical for 1 and 2 threads")


def main():
    if len(sys.argv) < 4:
        print(__doc__)
        return 2
    navsim, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    contract(navsim, work, [a for a in sys.argv[3:] if a.endswith(".yaml")][0])
    if shutil.which("rnx2rtkp") is None:
        print("SKIP: rnx2rtkp (Debian package rtklib) is not installed: the RINEX export is not "
              "checked against RTKLIB")
        return 77
    ideal = False
    max_m = 0.01
    weights_differ = False
    args = sys.argv[3:]
    i = 0
    while i < len(args):
        if args[i] == "--ideal":
            ideal = True
        elif args[i] == "--weights-differ":
            weights_differ = True
        elif args[i] == "--max-cm":
            i += 1
            max_m = float(args[i]) / 100.0
        else:
            run_scene(navsim, work, args[i], ideal, max_m, weights_differ)
        i += 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
