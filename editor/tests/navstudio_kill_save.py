#!/usr/bin/env python3
"""navstudio killed (SIGKILL) during its own save or autosave never leaves a torn or empty scene.

Issue 19 item 7. The test drives the real navstudio program (X display from $DISPLAY):

  navstudio SCENE with NAVSTUDIO_TEST_SAVE_LOOP=save|autosave changes the scene's seed and undoes
  the change in turn, saving (File > Save) or autosaving after each change, and writes each file
  slowly (NAVSTUDIO_TEST_SLOW_WRITE_US: small pieces with a pause between them, as on a slow
  disk), reporting "write begin" / "write end" on stderr, so that many kills land inside a write.

Each of KILLS rounds (save and autosave in turn) restores the scene file, starts navstudio, waits
for its loop to start and kills it with SIGKILL after a random delay (seeded): in half of the
rounds a delay from the loop's start, in the other half a delay from the start of its 1st to 3rd
write, shorter than a write lasts, so that the kills aim at the writes. Then:
  - the scene file and the autosave file (when there is one) read with `navsim check` and are
    byte for byte one of the complete texts the same loop writes when it is not killed (the old
    text or the new one; calibration runs record them);
  - a temporary file left by the kill is hidden (a dot file) and the next navstudio removes it
    when it starts; after the last round a final start leaves no temporary file at all.
The test fails unless at least a third of the kills landed inside a write.
"""
import argparse
import glob
import os
import random
import shutil
import signal
import subprocess
import sys
import threading
import time


def fail(msg):
    print("FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


class Studio:
    """One navstudio process with its stderr collected by a thread."""

    def __init__(self, exe, scene, env):
        self.lines = []
        self.ready = threading.Event()
        self.begins = 0
        self.changed = threading.Condition()
        self.proc = subprocess.Popen([exe, scene], env=env, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.PIPE, text=True, errors="replace")
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.proc.stderr:
            self.lines.append(line.rstrip("\n"))
            if "save loop ready" in line:
                self.ready.set()
            if line.startswith("navstudio: test: write begin "):
                with self.changed:
                    self.begins += 1
                    self.changed.notify_all()

    def wait_write_begin(self, n, timeout_s):
        """Wait until the n-th write has begun."""
        with self.changed:
            return self.changed.wait_for(lambda: self.begins >= n, timeout_s)

    def wait_ready(self, timeout_s):
        return self.ready.wait(timeout_s)

    def finish(self, timeout_s=60):
        code = self.proc.wait(timeout=timeout_s)
        self.reader.join(timeout=10)
        return code

    def in_write(self, folder):
        """Whether the last write reported of a file in @p folder began and did not end."""
        state = False
        for line in self.lines:
            for mark, value in (("navstudio: test: write begin ", True), ("navstudio: test: write end ", False)):
                if line.startswith(mark) and os.path.dirname(line[len(mark):]) == folder:
                    state = value
        return state


def read(path):
    try:
        with open(path, "rb") as f:
            return f.read()
    except FileNotFoundError:
        return None


def litter(dirs):
    """Files of the scene and autosave folders that are neither a scene nor an autosave."""
    out = []
    for d in dirs:
        for name in sorted(os.listdir(d)):
            if not name.endswith(".yaml") or name.startswith("."):
                out.append(os.path.join(d, name))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--navstudio", required=True)
    ap.add_argument("--navsim", required=True)
    ap.add_argument("--scene", required=True, help="scene to copy and save (a waypoint drive)")
    ap.add_argument("--work", required=True, help="scratch folder (emptied)")
    ap.add_argument("--kills", type=int, default=40)
    ap.add_argument("--seed", type=int, default=19007)
    ap.add_argument("--max-delay-s", type=float, default=1.0)
    ap.add_argument("--slow-write-us", type=int, default=4000)
    ap.add_argument("--write-window-s", type=float, default=0.15,
                    help="kills aimed at a write come this long after its start at most")
    a = ap.parse_args()

    if not os.environ.get("DISPLAY"):
        fail("no X display ($DISPLAY)")
    a.work = os.path.abspath(a.work)
    shutil.rmtree(a.work, ignore_errors=True)
    scene_dir = os.path.join(a.work, "scenes")
    auto_dir = os.path.join(a.work, "autosave")
    os.makedirs(scene_dir)
    os.makedirs(auto_dir)
    scene = os.path.join(scene_dir, "drive.yaml")
    shutil.copyfile(a.scene, scene)
    original = read(scene)

    env = dict(os.environ)
    env.update({
        "XDG_CONFIG_HOME": os.path.join(a.work, "config"),
        "XDG_DATA_HOME": os.path.join(a.work, "data"),
        "NAVSTUDIO_AUTOSAVE_DIR": auto_dir,
        "NAVSTUDIO_AUTOSAVE_MS": "3600000",  # only the loop's autosaves
        "NAVSTUDIO_TEST_SLOW_WRITE_US": str(a.slow_write_us),
    })

    def restore_scene():
        with open(scene, "wb") as f:
            f.write(original)

    def autosave_file():
        files = glob.glob(os.path.join(auto_dir, "autosave-*.yaml"))
        if len(files) > 1:
            fail("more than one autosave file: %s" % files)
        return files[0] if files else None

    def check_parses(path, what):
        r = subprocess.run([a.navsim, "check", path], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True)
        if r.returncode != 0:
            fail("%s: navsim check exit %d: %s" % (what, r.returncode, r.stdout.strip()[-600:]))

    # Calibration: the complete texts the loops write when they are not killed.
    def calibrate(mode, cycles):
        restore_scene()
        e = dict(env, NAVSTUDIO_TEST_SAVE_LOOP=mode, NAVSTUDIO_TEST_SAVE_LOOP_CYCLES=str(cycles))
        s = Studio(a.navstudio, scene, e)
        code = s.finish(timeout_s=300)
        if code != 0:
            fail("calibration %s %d: navstudio exit %s:\n%s" % (mode, cycles, code, "\n".join(s.lines[-20:])))
        return read(scene) if mode == "save" else read(autosave_file() or "/nonexistent")

    saved = {calibrate("save", 1), calibrate("save", 2)}
    autosaved = {calibrate("autosave", 1), calibrate("autosave", 2)}
    if None in saved or None in autosaved:
        fail("a calibration run wrote no file")
    scene_texts = saved | {original}
    if len(scene_texts) < 2 or len(autosaved) != 2:
        fail("the loop's texts do not differ (save %d, autosave %d distinct)" % (len(scene_texts), len(autosaved)))
    for i, t in enumerate(sorted(scene_texts | autosaved)):
        p = os.path.join(a.work, "valid-%d.yaml" % i)
        with open(p, "wb") as f:
            f.write(t)
        check_parses(p, "calibration text %d" % i)
        os.remove(p)
    print("calibration: %d scene texts (%s bytes), %d autosave texts (%s bytes)" %
          (len(scene_texts), "/".join(str(len(t)) for t in sorted(scene_texts, key=len)), len(autosaved),
           "/".join(str(len(t)) for t in sorted(autosaved, key=len))))
    for p in glob.glob(os.path.join(auto_dir, "*")):
        os.remove(p)

    rng = random.Random(a.seed)
    mid_write = 0
    left = []  # temporary files the previous kill left
    cleaned = 0
    for k in range(a.kills):
        mode = "save" if k % 2 == 0 else "autosave"
        restore_scene()
        auto_before = autosave_file()
        auto_before_text = read(auto_before) if auto_before else None
        e = dict(env, NAVSTUDIO_TEST_SAVE_LOOP=mode)
        s = Studio(a.navstudio, scene, e)
        if not s.wait_ready(120):
            s.proc.kill()
            s.finish()
            fail("kill %d: navstudio did not start its loop:\n%s" % (k, "\n".join(s.lines[-20:])))
        # The next start removes what a killed save left.
        still = [p for p in left if os.path.exists(p)]
        if still:
            s.proc.kill()
            s.finish()
            fail("kill %d: the temporary files of the previous kill were not removed on start: %s" % (k, still))
        cleaned += len(left)
        if k % 4 < 2:
            delay = rng.uniform(0.0, a.max_delay_s)
        else:
            nth = rng.randint(1, 3)
            if not s.wait_write_begin(nth, 120):
                s.proc.kill()
                s.finish()
                fail("kill %d: navstudio did not begin write %d:\n%s" % (k, nth, "\n".join(s.lines[-20:])))
            delay = rng.uniform(0.0, a.write_window_s)
        time.sleep(delay)
        s.proc.send_signal(signal.SIGKILL)
        code = s.finish()
        if code != -signal.SIGKILL:
            fail("kill %d: navstudio ended with %s before the kill:\n%s" % (k, code, "\n".join(s.lines[-20:])))
        inside = s.in_write(scene_dir if mode == "save" else auto_dir)
        mid_write += 1 if inside else 0

        text = read(scene)
        if text is None:
            fail("kill %d (%s, %.3f s): the scene file is gone" % (k, mode, delay))
        if mode == "save":
            if text not in scene_texts:
                fail("kill %d (save, %.3f s, %s): the scene file is torn (%d bytes, neither the old nor the new "
                     "text)" % (k, delay, "inside a write" if inside else "between writes", len(text)))
        elif text != original:
            fail("kill %d (autosave, %.3f s): an autosave changed the scene file" % (k, delay))
        check_parses(scene, "kill %d scene" % k)
        auto = autosave_file()
        if mode == "autosave" and auto:
            at = read(auto)
            if at not in autosaved:
                fail("kill %d (autosave, %.3f s, %s): the autosave is torn (%d bytes; before: %s)" %
                     (k, delay, "inside a write" if inside else "between writes", len(at),
                      "none" if auto_before_text is None else "%d bytes" % len(auto_before_text)))
            check_parses(auto, "kill %d autosave" % k)
        left = litter([scene_dir, auto_dir])
        visible = [p for p in left if not os.path.basename(p).startswith(".")]
        if visible:
            fail("kill %d: files a user would see besides the scene: %s" % (k, visible))
        print("kill %2d %-8s %s %.3f s: %s; scene %d bytes%s%s" %
              (k, mode, "after the start" if k % 4 < 2 else "into a write", delay,
               "inside a write" if inside else "between writes", len(text),
               "; autosave %d bytes" % len(read(auto)) if auto else "",
               "; left %d hidden temporary file(s)" % len(left) if left else ""))

    # A last start (the loop ends at once) removes the last kill's temporary files, and only
    # those of processes that no longer run: a temporary file of a running process (this test's
    # id stands for a navstudio saving at that moment) stays.
    restore_scene()
    done = subprocess.Popen(["true"])
    done.wait()
    dead = os.path.join(scene_dir, ".drive.yaml.navstudio-tmp-%d" % done.pid)
    alive = os.path.join(scene_dir, ".drive.yaml.navstudio-tmp-%d" % os.getpid())
    for p in (dead, alive):
        with open(p, "wb") as f:
            f.write(b"partial")
    s = Studio(a.navstudio, scene, dict(env, NAVSTUDIO_TEST_SAVE_LOOP="save", NAVSTUDIO_TEST_SAVE_LOOP_CYCLES="0"))
    if s.finish(timeout_s=300) != 0:
        fail("final start failed:\n" + "\n".join(s.lines[-20:]))
    cleaned += len(left)
    if os.path.exists(dead):
        fail("the temporary file of an ended process was not removed: %s" % dead)
    if not os.path.exists(alive):
        fail("the temporary file of a running process was removed: %s" % alive)
    os.remove(alive)
    rest = litter([scene_dir, auto_dir])
    if rest:
        fail("temporary files remain after a new start: %s" % rest)
    print("%d kills, %d inside a write, %d temporary files left by kills and removed by the next start" %
          (a.kills, mid_write, cleaned))
    if mid_write * 3 < a.kills:
        fail("only %d of %d kills landed inside a write: the test does not exercise the save" % (mid_write, a.kills))
    print("PASS")


if __name__ == "__main__":
    main()
