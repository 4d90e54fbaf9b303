#include "sim_worker.h"

#include <QMetaObject>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <type_traits>

#include <cerrno>
#include <csignal>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern "C" {
#include "navcore/nav_errors.h"
#include "navcore/nav_frames.h"
#include "navcore/nav_math.h"
}

namespace studio {

namespace {
struct RunCtx {
  std::atomic<double> *fraction;
  std::atomic<bool> *cancel;
  std::atomic<long> *beats; /* counts the callbacks: the parent's sign that the run moves */
  SimResult *out;
  double single_run_s; /* > 0: one run of this duration, whose progress the output epochs give */
  bool crash;          /* test hook: crash at the 10th output epoch of run 0 */
  long records;
};

nav_callback_result OnProgress(void *user, const nav_progress *p) {
  auto *c = static_cast<RunCtx *>(user);
  c->beats->fetch_add(1, std::memory_order_relaxed);
  if (p && std::isfinite(p->fraction)) c->fraction->store(p->fraction);
  return c->cancel->load() ? NAV_STOP : NAV_CONTINUE;
}

nav_callback_result OnRecord(void *user, const nav_sim_record *r) {
  auto *c = static_cast<RunCtx *>(user);
  c->beats->fetch_add(1, std::memory_order_relaxed);
  if (r->run != 0) return NAV_CONTINUE;
  // NAVSTUDIO_TEST_CRASH_RUN: a crash in the middle of the run, as a fault in navcore would be.
  if (c->crash && ++c->records == 10) raise(SIGSEGV);
  // navcore reports progress every 65536 IMU samples: a preview's single run is done sooner.
  if (c->single_run_s > 0.0) c->fraction->store(std::min(1.0, r->truth->t_s / c->single_run_s));
  const nav_local_view tv =
      nav_frame_view(r->frame, r->truth->r_fb_f_m, r->truth->v_fb_f_mps, r->truth->q_b_f);
  const nav_local_view nv = nav_frame_view(r->frame, r->nav->r_fb_f_m, r->nav->v_fb_f_mps, r->nav->q_b_f);
  SimResult *o = c->out;
  o->t_s.push_back(r->truth->t_s);
  o->truth_ned.insert(o->truth_ned.end(), {tv.r_ned_m.x, tv.r_ned_m.y, tv.r_ned_m.z});
  o->nav_ned.insert(o->nav_ned.end(), {nv.r_ned_m.x, nv.r_ned_m.y, nv.r_ned_m.z});
  o->err_h_m.push_back(r->err->pos_err_h_m);
  const nav_euler te = nav_quat_to_euler(tv.q_b_n, nullptr), ne = nav_quat_to_euler(nv.q_b_n, nullptr);
  o->truth_euler.insert(o->truth_euler.end(), {te.roll_rad, te.pitch_rad, te.yaw_rad});
  o->nav_euler.insert(o->nav_euler.end(), {ne.roll_rad, ne.pitch_rad, ne.yaw_rad});
  o->err_ned_m.insert(o->err_ned_m.end(),
                      {r->err->pos_err_n_m.x, r->err->pos_err_n_m.y, r->err->pos_err_n_m.z});
  o->err_v_m.push_back(r->err->pos_err_v_m);
  o->att_err_rad.push_back(r->err->att_err_rad);
  o->err_vel_mps.push_back(r->err->vel_err_mps);
  o->euler_err_rad.insert(o->euler_err_rad.end(), {r->err->euler_err.roll_rad, r->err->euler_err.pitch_rad,
                                                   r->err->euler_err.yaw_rad});
  return c->cancel->load() ? NAV_STOP : NAV_CONTINUE;
}
} // namespace

SimWorker::SimWorker(QObject *parent) : QObject(parent) {
  qRegisterMetaType<std::shared_ptr<const studio::SimResult>>();
  poll_.setInterval(50);
  connect(&poll_, &QTimer::timeout, this, [this] { emit Progress(Fraction()); });
  // The helper process is started now, while this program is small (forking it later, with the
  // views' memory, would cost each start milliseconds); its page of progress atomics is shared.
  void *page = mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (page != MAP_FAILED) {
    shared_page_ = new (page) Shared;
    QString err;
    StartHelper(&err); // on failure the first run starts it (and reports why not)
  }
}

SimWorker::~SimWorker() {
  queued_.reset();
  Cancel();
  if (thread_.joinable()) thread_.join();
  StopHelper();
  if (shared_page_) {
    shared_page_->~Shared();
    munmap(shared_page_, sizeof(Shared));
  }
}

void SimWorker::Start(const nav_scene &scene, long runs, bool preview, qint64 stamp, bool preempt) {
  auto job = std::make_unique<Job>();
  job->scene = std::make_unique<nav_scene>(scene);
  job->runs = runs < 1 ? 1 : runs;
  job->scene->simulation.runs = job->runs;
  job->preview = preview;
  job->stamp = stamp;
  // Test hook: NAVSTUDIO_TEST_CRASH_RUN=run (Monte Carlo runs), preview, or all makes the run
  // crash with SIGSEGV in its process (read at each start, so a test can switch it).
  const QByteArray crash = qgetenv("NAVSTUDIO_TEST_CRASH_RUN");
  job->crash_for_test = crash == "all" || (crash == "run" && !preview) || (crash == "preview" && preview);
  if (busy_) {
    queued_ = std::move(job);
    if (preempt) {
      cancel_.store(true);
      std::lock_guard<std::mutex> lock(sim_mutex_);
      if (shared_) shared_->cancel.store(true);
    }
    return;
  }
  Launch(std::move(job));
}

void SimWorker::Cancel() {
  queued_.reset();
  cancel_.store(true);
  std::lock_guard<std::mutex> lock(sim_mutex_);
  if (shared_) shared_->cancel.store(true);
}

double SimWorker::Fraction() const {
  std::lock_guard<std::mutex> lock(sim_mutex_);
  return shared_ ? shared_->fraction.load() : fraction_.load();
}

void SimWorker::Join() {
  if (thread_.joinable()) thread_.join();
}

void SimWorker::Launch(std::unique_ptr<Job> job) {
  if (thread_.joinable()) thread_.join();
  busy_ = true;
  cancel_.store(false);
  fraction_.store(0.0);
  running_ = std::move(job);
  Job *j = running_.get();
  emit Started();
  poll_.start();
  const bool hold = hold_next_.exchange(false);
  thread_ = std::thread([this, j, hold] {
    auto result = std::make_shared<SimResult>();
    // HoldNextJobForTest: wait for the cancel; the job then goes to the helper cancelled.
    for (int ms = 0; hold && ms < 60000 && !cancel_.load(); ++ms)
      usleep(1000);
    RunInHelper(j, result.get());
    std::shared_ptr<const SimResult> done = result;
    // The one crossing to the GUI thread: a queued call on this object (dropped if it is gone).
    QMetaObject::invokeMethod(
        this, [this, done] { OnThreadDone(done); }, Qt::QueuedConnection);
  });
}

void SimWorker::OnThreadDone(std::shared_ptr<const SimResult> r) {
  if (thread_.joinable()) thread_.join();
  poll_.stop();
  busy_ = false;
  running_.reset();
  fraction_.store(1.0);
  emit Finished(r);
  if (queued_ && !busy_) Launch(std::move(queued_));
}

namespace {

/* The run itself, in the helper process: navcore and the standard library only (a child forked
 * from a threaded program uses nothing another thread may have held: no Qt, no locks of the
 * parent). @p detail gets navcore's message of a failed run. */
int RunCore(const nav_scene &scene, long runs, bool preview, bool crash, std::atomic<double> *fraction,
            std::atomic<bool> *cancel, std::atomic<long> *beats, SimResult *out, std::string *detail) {
  nav_sim *sim = nullptr;
  nav_status st = nav_sim_create(&scene, &sim);
  if (st != NAV_OK) {
    *detail = "cannot start the simulation";
    return st;
  }
  // A cancel from the window reaches navcore within a few milliseconds, whichever run is on
  // (the callbacks see it only at run 0's epochs and at the progress reports).
  std::atomic<bool> finished{false};
  std::thread watch([&] {
    while (!finished.load()) {
      if (cancel->load()) {
        nav_sim_request_cancel(sim);
        return;
      }
      usleep(5000);
    }
  });

  // The live preview shows the estimate and the final error, not verdicts: no evaluator.
  nav_req_evaluator *ev = nullptr;
  if (!preview && scene.n_requirements > 0 &&
      nav_req_evaluator_create_for_scene(&scene, false, &ev) != NAV_OK)
    ev = nullptr;

  RunCtx ctx{fraction, cancel, beats, out, runs == 1 ? scene.trajectory.duration_s : 0.0, crash, 0};
  nav_sim_options o = nav_sim_options_default();
  const unsigned hc = std::thread::hardware_concurrency();
  o.threads = preview ? 1 : static_cast<int>(hc > 0 ? hc : 1);
  // The preview shows the output epochs and the final error: no reference states and errors
  // at the IMU epochs between them for statistics nobody reads (a third of its run).
  if (preview) o.stats_stride_min = std::llround(scene.imu.rate_hz / scene.output.rate_hz);
  o.progress = OnProgress;
  o.record = OnRecord;
  o.user = &ctx;
  nav_run_observer obs;
  if (ev) {
    obs = nav_req_evaluator_observer(ev);
    o.observer = &obs;
  }
  st = nav_sim_run(sim, &o, &out->summary);
  finished.store(true);
  watch.join();
  if (st != NAV_OK) {
    const char *d = nav_sim_last_error(sim);
    *detail = d ? d : "";
  } else {
    size_t n = 0;
    const nav_sim_envelope_point *env = nav_sim_envelope(sim, &n);
    for (size_t i = 0; env && i < n; ++i) {
      out->env_t_s.push_back(env[i].t_s);
      out->env_h_rms_m.push_back(env[i].pos_h_rms_m);
      out->env_rms_ned_m.insert(out->env_rms_ned_m.end(),
                                {env[i].pos_rms_n_m.x, env[i].pos_rms_n_m.y, env[i].pos_rms_n_m.z});
      out->env_att_rms_rad.push_back(env[i].att_rms_rad);
      out->env_vel_rms_mps.push_back(env[i].vel_rms_mps);
      if (scene.navigation.scheme == NAV_SCHEME_INS_GNSS ||
          scene.navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
          scene.navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) {
        out->env_sd_h_m.push_back(std::hypot(env[i].pos_sd_reported_n_m.x, env[i].pos_sd_reported_n_m.y));
        out->env_sd_ned_m.insert(
            out->env_sd_ned_m.end(),
            {env[i].pos_sd_reported_n_m.x, env[i].pos_sd_reported_n_m.y, env[i].pos_sd_reported_n_m.z});
      }
    }
    if (ev) {
      out->verdicts.resize(static_cast<size_t>(nav_req_evaluator_count(ev)));
      if (nav_req_evaluator_finish(ev, out->verdicts.data()) != NAV_OK) out->verdicts.clear();
    }
  }
  nav_sim_destroy(sim);
  nav_req_evaluator_destroy(ev);
  return st;
}

// The per-epoch series a result carries from the helper to the window, in this order.
std::vector<double> SimResult::*const kSeries[] = {&SimResult::t_s,
                                                   &SimResult::truth_ned,
                                                   &SimResult::nav_ned,
                                                   &SimResult::err_h_m,
                                                   &SimResult::truth_euler,
                                                   &SimResult::nav_euler,
                                                   &SimResult::err_ned_m,
                                                   &SimResult::err_v_m,
                                                   &SimResult::att_err_rad,
                                                   &SimResult::err_vel_mps,
                                                   &SimResult::euler_err_rad,
                                                   &SimResult::env_rms_ned_m,
                                                   &SimResult::env_att_rms_rad,
                                                   &SimResult::env_vel_rms_mps,
                                                   &SimResult::env_sd_ned_m,
                                                   &SimResult::env_t_s,
                                                   &SimResult::env_h_rms_m,
                                                   &SimResult::env_sd_h_m};
constexpr uint32_t kMagic = 0x4e535231u; /* "NSR1" */
static_assert(std::is_trivially_copyable<nav_sim_summary>::value, "the summary crosses the pipe as bytes");
static_assert(std::is_trivially_copyable<nav_requirement_verdict>::value, "verdicts cross the pipe as bytes");

void Put(std::vector<char> *b, const void *p, size_t n) {
  const char *c = static_cast<const char *>(p);
  b->insert(b->end(), c, c + n);
}

/* The result as bytes: magic, status, summary, detail, the series, the verdicts, magic. */
std::vector<char> Encode(int status, const std::string &detail, const SimResult &r) {
  std::vector<char> b;
  const int32_t st = status;
  Put(&b, &kMagic, sizeof kMagic);
  Put(&b, &st, sizeof st);
  Put(&b, &r.summary, sizeof r.summary);
  uint64_t n = detail.size();
  Put(&b, &n, sizeof n);
  Put(&b, detail.data(), detail.size());
  for (auto m : kSeries) {
    const std::vector<double> &v = r.*m;
    n = v.size();
    Put(&b, &n, sizeof n);
    Put(&b, v.data(), v.size() * sizeof(double));
  }
  n = r.verdicts.size();
  Put(&b, &n, sizeof n);
  Put(&b, r.verdicts.data(), r.verdicts.size() * sizeof(nav_requirement_verdict));
  Put(&b, &kMagic, sizeof kMagic);
  return b;
}

/* Decode what Encode wrote; false when the bytes are short or malformed. */
bool Decode(const std::vector<char> &b, int *status, std::string *detail, SimResult *r) {
  size_t at = 0;
  auto get = [&](void *p, size_t n) {
    if (n > b.size() - at) return false;
    std::memcpy(p, b.data() + at, n);
    at += n;
    return true;
  };
  auto count = [&](uint64_t *n, size_t elem) { return get(n, sizeof *n) && *n <= (b.size() - at) / elem; };
  uint32_t magic = 0;
  int32_t st = 0;
  uint64_t n = 0;
  if (!get(&magic, sizeof magic) || magic != kMagic || !get(&st, sizeof st) ||
      !get(&r->summary, sizeof r->summary))
    return false;
  if (!count(&n, 1)) return false;
  detail->assign(b.data() + at, static_cast<size_t>(n));
  at += static_cast<size_t>(n);
  for (auto m : kSeries) {
    std::vector<double> &v = r->*m;
    if (!count(&n, sizeof(double))) return false;
    v.resize(static_cast<size_t>(n));
    if (!get(v.data(), v.size() * sizeof(double))) return false;
  }
  if (!count(&n, sizeof(nav_requirement_verdict))) return false;
  r->verdicts.resize(static_cast<size_t>(n));
  if (!get(r->verdicts.data(), r->verdicts.size() * sizeof(nav_requirement_verdict))) return false;
  if (!get(&magic, sizeof magic) || magic != kMagic || at != b.size()) return false;
  *status = st;
  return true;
}

const char *SignalText(int sig) {
  switch (sig) {
  case SIGSEGV: return "SIGSEGV, a segmentation fault";
  case SIGBUS: return "SIGBUS, a bus error";
  case SIGFPE: return "SIGFPE, an arithmetic fault";
  case SIGILL: return "SIGILL, an illegal instruction";
  case SIGABRT: return "SIGABRT, an abort";
  case SIGKILL: return "SIGKILL, killed (out of memory?)";
  default: return "a signal";
  }
}

bool WriteAll(int fd, const void *p, size_t n, bool nosignal) {
  const char *c = static_cast<const char *>(p);
  while (n > 0) {
    // The window's side never takes SIGPIPE from a helper that died (MSG_NOSIGNAL).
    const ssize_t w = nosignal ? send(fd, c, n, MSG_NOSIGNAL) : write(fd, c, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    c += w;
    n -= static_cast<size_t>(w);
  }
  return true;
}

bool ReadAll(int fd, void *p, size_t n) {
  char *c = static_cast<char *>(p);
  while (n > 0) {
    const ssize_t r = read(fd, c, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    c += r;
    n -= static_cast<size_t>(r);
  }
  return true;
}

/* What the window sends the helper per run: this header, the scene's bytes, then a recorded
 * reference's control points (count x (3 + 4) doubles; the scene's pointers are not sent). */
struct JobHeader {
  uint32_t magic;
  int32_t runs;
  uint8_t preview, crash;
  uint64_t n_ctrl; /* control points that follow the scene (0: none) */
};

/* The helper process: runs the jobs the window sends on fd 3, one at a time, and answers each
 * with its encoded result (a 64-bit length, then Encode's bytes). It ends at the end of its
 * input (the window closed it or is gone) and, like any process, with a fault in a run: the
 * window then reports the crash and starts another helper. Only system calls and RunCore. */
[[noreturn]] void HelperMain(int fd, SimWorker::Shared *sh) {
  // A fault ends this process with its signal (no handler of the window's, no core file).
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGPIPE, SIGTERM, SIGINT, SIGCHLD})
    std::signal(sig, SIG_DFL);
  sigset_t none;
  sigemptyset(&none);
  pthread_sigmask(SIG_SETMASK, &none, nullptr);
  const struct rlimit no_core = {0, 0};
  setrlimit(RLIMIT_CORE, &no_core);
  // The socket becomes fd 3; every other descriptor of the window is closed (another helper's
  // socket left open here would hide that helper's end from the window).
  if (fd != 3 && dup2(fd, 3) < 0) _exit(126);
  if (close_range(4, ~0U, 0) != 0)
    for (int f = 4; f < 4096; ++f)
      close(f);
  for (;;) {
    JobHeader h{};
    auto scene = std::make_unique<nav_scene>();
    if (!ReadAll(3, &h, sizeof h) || h.magic != kMagic || !ReadAll(3, scene.get(), sizeof(nav_scene)))
      _exit(0);
    std::vector<nav_vec3> ctrl_ned;
    std::vector<nav_quat> ctrl_q;
    nav_traj_recorded &rec = scene->trajectory.recorded;
    if (h.n_ctrl > (1ull << 28)) _exit(0);
    const size_t nc = static_cast<size_t>(h.n_ctrl);
    ctrl_ned.resize(nc);
    ctrl_q.resize(nc);
    if (nc > 0 && (!ReadAll(3, ctrl_ned.data(), nc * sizeof(nav_vec3)) ||
                   !ReadAll(3, ctrl_q.data(), nc * sizeof(nav_quat))))
      _exit(0);
    // A borrowed view of the control points (never released here).
    rec.ctrl_ned_m = nc > 0 ? ctrl_ned.data() : nullptr;
    rec.ctrl_q = nc > 0 ? ctrl_q.data() : nullptr;
    SimResult out;
    std::string detail;
    const int st = RunCore(*scene, h.runs, h.preview != 0, h.crash != 0, &sh->fraction, &sh->cancel,
                           &sh->beats, &out, &detail);
    const std::vector<char> b = Encode(st, detail, out);
    const uint64_t len = b.size();
    if (!WriteAll(3, &len, sizeof len, false) || !WriteAll(3, b.data(), b.size(), false)) _exit(0);
  }
}

} // namespace

bool SimWorker::StartHelper(QString *error) {
  int sv[2] = {-1, -1};
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0) {
    *error = QStringLiteral("cannot start the simulation process: %1")
                 .arg(QString::fromLocal8Bit(std::strerror(errno)));
    return false;
  }
  const pid_t pid = fork();
  if (pid == 0) {
    close(sv[0]);
    HelperMain(sv[1], shared_page_);
  }
  const int e = errno;
  close(sv[1]);
  if (pid < 0) {
    close(sv[0]);
    *error = QStringLiteral("cannot start the simulation process: %1")
                 .arg(QString::fromLocal8Bit(std::strerror(e)));
    return false;
  }
  helper_pid_ = pid;
  helper_fd_ = sv[0];
  return true;
}

double SimWorker::HelperCpuS() const {
  const pid_t pid = helper_pid_.load();
  if (pid <= 0) return 0.0;
  char path[64];
  std::snprintf(path, sizeof path, "/proc/%d/stat", static_cast<int>(pid));
  FILE *f = std::fopen(path, "r");
  if (!f) return 0.0;
  char buf[1024];
  const size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  buf[n] = '\0';
  // Fields after the command name (in parentheses): state is the 3rd, utime and stime the 14th
  // and 15th, in clock ticks.
  const char *p = std::strrchr(buf, ')');
  unsigned long long ut = 0, st = 0;
  if (!p || std::sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &ut, &st) != 2)
    return 0.0;
  return static_cast<double>(ut + st) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

void SimWorker::StopHelper() {
  if (helper_fd_ >= 0) close(helper_fd_);
  helper_fd_ = -1;
  if (helper_pid_ > 0) {
    kill(helper_pid_, SIGKILL);
    while (waitpid(helper_pid_, nullptr, 0) < 0 && errno == EINTR) {
    }
  }
  helper_pid_ = -1;
}

void SimWorker::RunInHelper(Job *job, SimResult *out) {
  const auto t0 = std::chrono::steady_clock::now();
  out->preview = job->preview;
  out->runs = job->runs;
  out->scene_change_ns = job->stamp;
  const nav_scene &scene = *job->scene;
  if (scene.gnss.enabled)
    out->outages.assign(scene.gnss.model.outages, scene.gnss.model.outages + scene.gnss.model.outage_count);
  auto wall = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  Shared *sh = shared_page_;
  if (!sh) {
    out->status = NAV_ERR_NO_MEMORY;
    out->message = QStringLiteral("cannot start the simulation process: no shared memory");
    out->wall_s = wall();
    return;
  }
  {
    std::lock_guard<std::mutex> lock(sim_mutex_);
    sh->fraction.store(0.0);
    sh->beats.store(0);
    sh->cancel.store(cancel_.load());
    shared_ = sh;
  }
  // The job to the helper (started again when an earlier run crashed it).
  const nav_traj_recorded &rec = scene.trajectory.recorded;
  const size_t nc = rec.ctrl_ned_m && rec.ctrl_q && rec.count > 0 ? static_cast<size_t>(rec.count) : 0;
  const JobHeader h{kMagic, static_cast<int32_t>(std::min<long>(job->runs, INT32_MAX)),
                    uint8_t(job->preview ? 1 : 0), uint8_t(job->crash_for_test ? 1 : 0), nc};
  auto send_job = [&] {
    return WriteAll(helper_fd_, &h, sizeof h, true) && WriteAll(helper_fd_, &scene, sizeof scene, true) &&
           (nc == 0 || (WriteAll(helper_fd_, rec.ctrl_ned_m, nc * sizeof(nav_vec3), true) &&
                        WriteAll(helper_fd_, rec.ctrl_q, nc * sizeof(nav_quat), true)));
  };
  QString err;
  bool sent_ok = false;
  for (int attempt = 0; attempt < 2 && !sent_ok; ++attempt) {
    if (helper_fd_ < 0 && !StartHelper(&err)) break;
    sent_ok = send_job();
    if (!sent_ok) StopHelper(); // the helper had ended: one more with a new one
  }
  std::vector<char> data;
  bool stalled = false, complete = false;
  if (sent_ok) {
    // The answer: its length, then its bytes. A run whose callbacks stop for kStallS (a hang)
    // is ended: the worker stays usable.
    uint64_t want = 0;
    size_t have_len = 0;
    char buf[65536];
    long beats = -1;
    auto last_beat = std::chrono::steady_clock::now();
    for (;;) {
      pollfd pf{helper_fd_, POLLIN, 0};
      const int r = poll(&pf, 1, 50);
      fraction_.store(sh->fraction.load());
      const long b = sh->beats.load();
      const auto now = std::chrono::steady_clock::now();
      if (b != beats || r > 0) {
        beats = b;
        last_beat = now;
      } else if (!stalled && std::chrono::duration<double>(now - last_beat).count() > kStallS) {
        kill(helper_pid_, SIGKILL);
        stalled = true;
      }
      if (r == 0 || (r < 0 && errno == EINTR)) continue;
      const size_t room = have_len < sizeof want
                              ? sizeof want - have_len
                              : static_cast<size_t>(std::min<uint64_t>(sizeof buf, want - data.size()));
      const ssize_t n =
          read(helper_fd_, have_len < sizeof want ? reinterpret_cast<char *>(&want) + have_len : buf, room);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break; // the helper ended
      if (have_len < sizeof want) {
        have_len += static_cast<size_t>(n);
        if (have_len == sizeof want) data.reserve(static_cast<size_t>(std::min<uint64_t>(want, 1ull << 31)));
      } else {
        data.insert(data.end(), buf, buf + n);
      }
      if (have_len == sizeof want && data.size() == want) {
        complete = true;
        break;
      }
    }
  }
  int wstatus = 0;
  bool ended = false;
  if (sent_ok && !complete) {
    // The helper ended during the run: collect how.
    close(helper_fd_);
    helper_fd_ = -1;
    while (waitpid(helper_pid_, &wstatus, 0) < 0 && errno == EINTR) {
    }
    helper_pid_ = -1;
    ended = true;
  }
  {
    std::lock_guard<std::mutex> lock(sim_mutex_);
    shared_ = nullptr;
  }

  int st = 0;
  std::string detail;
  if (!sent_ok) {
    out->status = NAV_ERR_NO_MEMORY;
    out->message = err.isEmpty() ? QStringLiteral("cannot start the simulation process") : err;
  } else if (stalled) {
    out->status = kStatusCrashed;
    out->crash_signal = SIGKILL;
    out->message =
        QStringLiteral("the simulation stopped responding for %1 s and was ended; navstudio kept running")
            .arg(kStallS, 0, 'f', 0);
  } else if (ended && WIFSIGNALED(wstatus)) {
    out->status = kStatusCrashed;
    out->crash_signal = WTERMSIG(wstatus);
    out->message = QStringLiteral("the simulation crashed (%1); navstudio kept running")
                       .arg(QString::fromLatin1(SignalText(out->crash_signal)));
  } else if (ended || !Decode(data, &st, &detail, out)) {
    out->status = kStatusCrashed;
    out->message = QStringLiteral("the simulation process ended without a result (exit code %1)")
                       .arg(ended && WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1);
  } else {
    out->status = st;
    if (st == NAV_ERR_CANCELLED)
      out->message = QStringLiteral("cancelled");
    else if (st != NAV_OK)
      out->message = QStringLiteral("simulation failed: %1%2%3")
                         .arg(QString::fromUtf8(nav_status_str(static_cast<nav_status>(st))),
                              detail.empty() ? "" : ": ", QString::fromUtf8(detail.c_str()));
  }
  out->wall_s = wall();
}

} // namespace studio
