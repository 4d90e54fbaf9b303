#include "sim_worker.h"

#include <QMetaObject>

#include <algorithm>
#include <chrono>
#include <cmath>

extern "C" {
#include "navcore/nav_errors.h"
#include "navcore/nav_frames.h"
#include "navcore/nav_math.h"
}

namespace studio {

namespace {
struct RunCtx {
  SimWorker *self;
  std::atomic<double> *fraction;
  std::atomic<bool> *cancel;
  SimResult *out;
  double single_run_s; /* > 0: one run of this duration, whose progress the output epochs give */
};

nav_callback_result OnProgress(void *user, const nav_progress *p) {
  auto *c = static_cast<RunCtx *>(user);
  if (p && std::isfinite(p->fraction)) c->fraction->store(p->fraction);
  return c->cancel->load() ? NAV_STOP : NAV_CONTINUE;
}

nav_callback_result OnRecord(void *user, const nav_sim_record *r) {
  auto *c = static_cast<RunCtx *>(user);
  if (r->run != 0) return NAV_CONTINUE;
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
  connect(&poll_, &QTimer::timeout, this, [this] { emit Progress(fraction_.load()); });
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
  if (busy_) {
    queued_ = std::move(job);
    if (preempt) {
      cancel_.store(true);
      std::lock_guard<std::mutex> lock(sim_mutex_);
      if (sim_) nav_sim_request_cancel(sim_);
    }
    return;
  }
  Launch(std::move(job));
}

void SimWorker::Cancel() {
  queued_.reset();
  cancel_.store(true);
  std::lock_guard<std::mutex> lock(sim_mutex_);
  if (sim_) nav_sim_request_cancel(sim_);
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
    RunJob(this, j, result.get());
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

void SimWorker::RunJob(SimWorker *self, Job *job, SimResult *out) {
  const auto t0 = std::chrono::steady_clock::now();
  out->preview = job->preview;
  out->runs = job->runs;
  out->scene_change_ns = job->stamp;
  const nav_scene &scene = *job->scene;
  if (scene.gnss.enabled)
    out->outages.assign(scene.gnss.model.outages, scene.gnss.model.outages + scene.gnss.model.outage_count);
  nav_sim *sim = nullptr;
  nav_status st = nav_sim_create(&scene, &sim);
  if (st != NAV_OK) {
    out->status = st;
    out->message = QStringLiteral("cannot start the simulation: %1").arg(nav_status_str(st));
    return;
  }
  {
    std::lock_guard<std::mutex> lock(self->sim_mutex_);
    self->sim_ = sim;
  }
  if (self->cancel_.load()) nav_sim_request_cancel(sim);

  // The live preview shows the estimate and the final error, not verdicts: no evaluator.
  nav_req_evaluator *ev = nullptr;
  if (!job->preview && scene.n_requirements > 0 && nav_req_evaluator_create_for_scene(&scene, false, &ev) != NAV_OK)
    ev = nullptr;

  RunCtx ctx{self, &self->fraction_, &self->cancel_, out, job->runs == 1 ? scene.trajectory.duration_s : 0.0};
  nav_sim_options o = nav_sim_options_default();
  const unsigned hc = std::thread::hardware_concurrency();
  o.threads = job->preview ? 1 : static_cast<int>(hc > 0 ? hc : 1);
  // The preview shows the output epochs and the final error: no reference states and errors
  // at the IMU epochs between them for statistics nobody reads (a third of its run).
  if (job->preview) o.stats_stride_min = std::llround(scene.imu.rate_hz / scene.output.rate_hz);
  o.progress = OnProgress;
  o.record = OnRecord;
  o.user = &ctx;
  nav_run_observer obs;
  if (ev) {
    obs = nav_req_evaluator_observer(ev);
    o.observer = &obs;
  }
  st = nav_sim_run(sim, &o, &out->summary);
  out->status = st;
  if (st != NAV_OK) {
    const char *detail = nav_sim_last_error(sim);
    out->message = st == NAV_ERR_CANCELLED ? QStringLiteral("cancelled")
                                           : QStringLiteral("simulation failed: %1%2%3")
                                                 .arg(nav_status_str(st), detail && detail[0] ? ": " : "",
                                                      QString::fromUtf8(detail ? detail : ""));
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
  {
    std::lock_guard<std::mutex> lock(self->sim_mutex_);
    self->sim_ = nullptr;
  }
  nav_sim_destroy(sim);
  nav_req_evaluator_destroy(ev);
  out->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace studio
