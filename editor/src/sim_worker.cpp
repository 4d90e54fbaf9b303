#include "sim_worker.h"

#include <QMetaObject>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>

#include <cerrno>
#include <csignal>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <sys/mman.h>
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
  const nav_local_view tv = nav_frame_view(r->frame, r->truth->r_fb_f_m, r->truth->v_fb_f_mps, r->truth->q_b_f);
  const nav_local_view nv = nav_frame_view(r->frame, r->nav->r_fb_f_m, r->nav->v_fb_f_mps, r->nav->q_b_f);
  SimResult *o = c->out;
  o->t_s.push_back(r->truth->t_s);
  o->truth_ned.insert(o->truth_ned.end(), {tv.r_ned_m.x, tv.r_ned_m.y, tv.r_ned_m.z});
  o->nav_ned.insert(o->nav_ned.end(), {nv.r_ned_m.x, nv.r_ned_m.y, nv.r_ned_m.z});
  o->err_h_m.push_back(r->err->pos_err_h_m);
  const nav_euler te = nav_quat_to_euler(tv.q_b_n, nullptr), ne = nav_quat_to_euler(nv.q_b_n, nullptr);
  o->truth_euler.insert(o->truth_euler.end(), {te.roll_rad, te.pitch_rad, te.yaw_rad});
  o->nav_euler.insert(o->nav_euler.end(), {ne.roll_rad, ne.pitch_rad, ne.yaw_rad});
  o->err_ned_m.insert(o->err_ned_m.end(), {r->err->pos_err_n_m.x, r->err->pos_err_n_m.y, r->err->pos_err_n_m.z});
  o->err_v_m.push_back(r->err->pos_err_v_m);
  o->att_err_rad.push_back(r->err->att_err_rad);
  o->err_vel_mps.push_back(r->err->vel_err_mps);
  o->euler_err_rad.insert(o->euler_err_rad.end(), {r->err->euler_err.roll_rad, r->err->euler_err.pitch_rad, r->err->euler_err.yaw_rad});
  return c->cancel->load() ? NAV_STOP : NAV_CONTINUE;
}
} // namespace

SimWorker::SimWorker(QObject *parent) : QObject(parent) {
  qRegisterMetaType<std::shared_ptr<const studio::SimResult>>();
  poll_.setInterval(50);
  connect(&poll_, &QTimer::timeout, this, [this] { emit Progress(Fraction()); });
}

SimWorker::~SimWorker() {
  queued_.reset();
  Cancel();
  if (thread_.joinable()) thread_.join();
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
  thread_ = std::thread([this, j] {
    auto result = std::make_shared<SimResult>();
    RunInChild(j, result.get());
    std::shared_ptr<const SimResult> done = result;
    // The one crossing to the GUI thread: a queued call on this object (dropped if it is gone).
    QMetaObject::invokeMethod(this, [this, done] { OnThreadDone(done); }, Qt::QueuedConnection);
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

/* The run itself, in the child process: navcore and the standard library only (a child forked
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
  if (!preview && scene.n_requirements > 0 && nav_req_evaluator_create_for_scene(&scene, false, &ev) != NAV_OK)
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
      out->env_rms_ned_m.insert(out->env_rms_ned_m.end(), {env[i].pos_rms_n_m.x, env[i].pos_rms_n_m.y, env[i].pos_rms_n_m.z});
      out->env_att_rms_rad.push_back(env[i].att_rms_rad);
      out->env_vel_rms_mps.push_back(env[i].vel_rms_mps);
      if (scene.navigation.scheme == NAV_SCHEME_INS_GNSS || scene.navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
          scene.navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) {
        out->env_sd_h_m.push_back(std::hypot(env[i].pos_sd_reported_n_m.x, env[i].pos_sd_reported_n_m.y));
        out->env_sd_ned_m.insert(out->env_sd_ned_m.end(), {env[i].pos_sd_reported_n_m.x, env[i].pos_sd_reported_n_m.y,
                                                           env[i].pos_sd_reported_n_m.z});
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

// The per-epoch series a result carries from the child to the parent, in this order.
std::vector<double> SimResult::*const kSeries[] = {
    &SimResult::t_s,           &SimResult::truth_ned,       &SimResult::nav_ned,       &SimResult::err_h_m,
    &SimResult::truth_euler,   &SimResult::nav_euler,       &SimResult::err_ned_m,     &SimResult::err_v_m,
    &SimResult::att_err_rad,   &SimResult::err_vel_mps,     &SimResult::euler_err_rad, &SimResult::env_rms_ned_m,
    &SimResult::env_att_rms_rad, &SimResult::env_vel_rms_mps, &SimResult::env_sd_ned_m, &SimResult::env_t_s,
    &SimResult::env_h_rms_m,   &SimResult::env_sd_h_m};
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
  if (!get(&magic, sizeof magic) || magic != kMagic || !get(&st, sizeof st) || !get(&r->summary, sizeof r->summary))
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

/* The child: run, send the result, end without running the parent's exit handlers. Only
 * system calls and RunCore. */
[[noreturn]] void ChildMain(int wfd, const nav_scene &scene, long runs, bool preview, bool crash,
                            std::atomic<double> *fraction, std::atomic<bool> *cancel, std::atomic<long> *beats,
                            SimResult *out) {
  // A fault ends this process with its signal (no handler of the parent's, no core file).
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGPIPE, SIGTERM, SIGINT})
    std::signal(sig, SIG_DFL);
  sigset_t none;
  sigemptyset(&none);
  pthread_sigmask(SIG_SETMASK, &none, nullptr);
  const struct rlimit no_core = {0, 0};
  setrlimit(RLIMIT_CORE, &no_core);
  // The result pipe becomes fd 3; every other descriptor of the parent is closed (another
  // worker's pipe left open here would keep that worker waiting for its end of file).
  if (wfd != 3) {
    if (dup2(wfd, 3) < 0) _exit(126);
  }
  if (close_range(4, ~0U, 0) != 0)
    for (int fd = 4; fd < 4096; ++fd)
      close(fd);
  std::string detail;
  const int st = RunCore(scene, runs, preview, crash, fraction, cancel, beats, out, &detail);
  const std::vector<char> b = Encode(st, detail, *out);
  size_t at = 0;
  while (at < b.size()) {
    const ssize_t w = write(3, b.data() + at, b.size() - at);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) _exit(125);
    at += static_cast<size_t>(w);
  }
  _exit(0);
}

} // namespace

void SimWorker::RunInChild(Job *job, SimResult *out) {
  const auto t0 = std::chrono::steady_clock::now();
  out->preview = job->preview;
  out->runs = job->runs;
  out->scene_change_ns = job->stamp;
  const nav_scene &scene = *job->scene;
  if (scene.gnss.enabled)
    out->outages.assign(scene.gnss.model.outages, scene.gnss.model.outages + scene.gnss.model.outage_count);
  auto wall = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };

  void *page = mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  int fds[2] = {-1, -1};
  if (page == MAP_FAILED || pipe2(fds, O_CLOEXEC) != 0) {
    const int e = errno;
    if (page != MAP_FAILED) munmap(page, sizeof(Shared));
    out->status = NAV_ERR_NO_MEMORY;
    out->message = QStringLiteral("cannot start the simulation process: %1").arg(QString::fromLocal8Bit(std::strerror(e)));
    out->wall_s = wall();
    return;
  }
  Shared *sh = new (page) Shared;
  {
    std::lock_guard<std::mutex> lock(sim_mutex_);
    sh->cancel.store(cancel_.load());
    shared_ = sh;
  }
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    ChildMain(fds[1], scene, job->runs, job->preview, job->crash_for_test, &sh->fraction, &sh->cancel, &sh->beats,
              out);
  }
  const int fork_errno = errno;
  close(fds[1]);
  std::vector<char> data;
  bool stalled = false;
  if (pid > 0) {
    char buf[65536];
    // A run whose callbacks stop for kStallS (a hang) is ended: the worker stays usable.
    long beats = -1;
    auto last_beat = std::chrono::steady_clock::now();
    for (;;) {
      pollfd pf{fds[0], POLLIN, 0};
      const int r = poll(&pf, 1, 50);
      fraction_.store(sh->fraction.load());
      const long b = sh->beats.load();
      const auto now = std::chrono::steady_clock::now();
      if (b != beats || r > 0) {
        beats = b;
        last_beat = now;
      } else if (!stalled && std::chrono::duration<double>(now - last_beat).count() > kStallS) {
        kill(pid, SIGKILL);
        stalled = true;
      }
      if (r == 0 || (r < 0 && errno == EINTR)) continue;
      const ssize_t n = read(fds[0], buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      data.insert(data.end(), buf, buf + n);
    }
  }
  close(fds[0]);
  int wstatus = 0;
  if (pid > 0)
    while (waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
    }
  {
    std::lock_guard<std::mutex> lock(sim_mutex_);
    shared_ = nullptr;
  }
  sh->~Shared();
  munmap(page, sizeof(Shared));

  int st = 0;
  std::string detail;
  if (pid < 0) {
    out->status = NAV_ERR_NO_MEMORY;
    out->message =
        QStringLiteral("cannot start the simulation process: %1").arg(QString::fromLocal8Bit(std::strerror(fork_errno)));
  } else if (stalled) {
    out->status = kStatusCrashed;
    out->crash_signal = SIGKILL;
    out->message = QStringLiteral("the simulation stopped responding for %1 s and was ended; navstudio kept running")
                       .arg(kStallS, 0, 'f', 0);
  } else if (WIFSIGNALED(wstatus)) {
    out->status = kStatusCrashed;
    out->crash_signal = WTERMSIG(wstatus);
    out->message = QStringLiteral("the simulation crashed (%1); navstudio kept running")
                       .arg(QString::fromLatin1(SignalText(out->crash_signal)));
  } else if (!WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0 || !Decode(data, &st, &detail, out)) {
    out->status = kStatusCrashed;
    out->message = QStringLiteral("the simulation process ended without a result (exit code %1)")
                       .arg(WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1);
  } else {
    out->status = st;
    if (st == NAV_ERR_CANCELLED)
      out->message = QStringLiteral("cancelled");
    else if (st != NAV_OK)
      out->message = QStringLiteral("simulation failed: %1%2%3")
                         .arg(QString::fromUtf8(nav_status_str(static_cast<nav_status>(st))), detail.empty() ? "" : ": ",
                              QString::fromUtf8(detail.c_str()));
  }
  out->wall_s = wall();
}

} // namespace studio
