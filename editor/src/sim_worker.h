/*
 * navstudio: simulation on a background thread (style.md section 7), run in a helper process.
 * Each SimWorker forks one helper process when it is created (while the program is small); its
 * worker thread sends each job (the scene's bytes) to the helper over a socket and reads back a
 * plain SimResult. The helper only calls navcore (nav_sim_run); a crash of a run (a signal in
 * navcore) ends the helper, never the window, and is reported as a failed run; the next job
 * starts a new helper. Progress and cancellation cross through a shared memory page of atomics;
 * the worker thread never touches Qt widgets or VTK. The result crosses to the GUI thread once,
 * through a queued call, as a shared_ptr to an immutable SimResult.
 */
#ifndef NAVSTUDIO_SIM_WORKER_H
#define NAVSTUDIO_SIM_WORKER_H

#include <QObject>
#include <QString>
#include <QTimer>

#include <sys/types.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

extern "C" {
#include "navcore/nav_requirements.h"
#include "navcore/nav_scene.h"
#include "navcore/nav_sim.h"
}

namespace studio {

/** SimResult::status of a run whose process crashed (killed by a signal) or ended without a
 *  complete result; not a nav_status. */
constexpr int kStatusCrashed = -1;

/** What a simulation produced (plain data; immutable once published). */
struct SimResult {
  bool preview = false;       /**< a single-run live preview */
  long runs = 0;              /**< runs requested */
  /** nav_status of nav_sim_run, or kStatusCrashed when the run's process ended abnormally */
  int status = 0;
  QString message;            /**< failure text ("" on success) */
  int crash_signal = 0;       /**< the signal that ended the run's process (kStatusCrashed) */
  nav_sim_summary summary{};  /**< navcore's summary */
  double wall_s = 0.0;        /**< wall time of the run [s] */
  qint64 scene_change_ns = 0; /**< SceneDocument::LastChangeNs() of the scene that was run */
  std::vector<double> t_s;        /**< run 0 output epochs */
  std::vector<double> truth_ned;  /**< 3 per epoch: reference, local NED [m] */
  std::vector<double> nav_ned;    /**< 3 per epoch: estimate of run 0, local NED [m] */
  std::vector<double> err_h_m;    /**< horizontal error of run 0 [m] */
  std::vector<double> truth_euler; /**< 3 per epoch: reference roll, pitch, yaw of C_b_n [rad] */
  std::vector<double> nav_euler;   /**< 3 per epoch: estimated roll, pitch, yaw of run 0 [rad] */
  std::vector<double> err_ned_m;   /**< 3 per epoch: position error N/E/D of run 0 [m] */
  std::vector<double> err_v_m;     /**< vertical error of run 0 [m] */
  std::vector<double> att_err_rad; /**< attitude error angle of run 0 [rad] */
  std::vector<double> err_vel_mps; /**< |velocity error| of run 0 [m/s] */
  std::vector<double> euler_err_rad; /**< 3 per epoch: roll/pitch/yaw error of run 0 [rad] */
  std::vector<double> env_rms_ned_m; /**< 3 per envelope epoch: RMS over runs of N/E/D error [m] */
  std::vector<double> env_att_rms_rad; /**< RMS over runs of the attitude error [rad] */
  std::vector<double> env_vel_rms_mps; /**< RMS over runs of |velocity error| [m/s] */
  std::vector<double> env_sd_ned_m;  /**< 3 per envelope epoch: filter's reported sigma N/E/D [m] */
  std::vector<double> env_t_s;    /**< Monte Carlo envelope epochs */
  std::vector<double> env_h_rms_m; /**< RMS over runs of the horizontal error [m] */
  /** The filter's reported horizontal 1-sigma, mean over runs [m] (INS/GNSS; else empty) */
  std::vector<double> env_sd_h_m;
  std::vector<nav_requirement_verdict> verdicts; /**< one per scene requirement (none for a preview) */
  std::vector<nav_gnss_outage> outages;          /**< the scene's GNSS outages (for charts) */
};

/**
 * Runs one simulation at a time on its own std::thread. Start() while running queues the new
 * request (a later one replaces an earlier queued one) and, when @p preempt, cancels the running
 * one. Finished(result) is emitted on the GUI thread.
 */
class SimWorker : public QObject {
  Q_OBJECT
public:
  explicit SimWorker(QObject *parent = nullptr);
  ~SimWorker() override;

  /** Run @p scene (copied) with @p runs runs; @p stamp is echoed in the result. */
  void Start(const nav_scene &scene, long runs, bool preview, qint64 stamp, bool preempt);
  /** Ask the running simulation to stop (thread-safe, returns at once); drops a queued one. */
  void Cancel();
  bool IsBusy() const { return busy_; }
  /** Fraction 0..1 of the running job. */
  double Fraction() const;
  /** Wait until the worker is idle (tests, shutdown); processes nothing. */
  void Join();
  /** CPU time the helper process that runs the simulations has used so far [s] (0 without one). */
  double HelperCpuS() const;
  /** Test hook: the next job started waits, before it reaches the helper process, until it is
   *  cancelled (at most 60 s), so that a test can issue the next edit while it is still running. */
  void HoldNextJobForTest() { hold_next_.store(true); }

signals:
  void Progress(double fraction);
  void Finished(std::shared_ptr<const studio::SimResult> result);
  void Started();

private:
  struct Job {
    std::unique_ptr<nav_scene> scene;
    long runs = 1;
    bool preview = false;
    qint64 stamp = 0;
    bool crash_for_test = false; /**< NAVSTUDIO_TEST_CRASH_RUN: the run crashes (SIGSEGV) */
  };
public:
  /** Progress and cancellation shared with the helper process (a MAP_SHARED page). */
  struct Shared {
    std::atomic<double> fraction{0.0};
    std::atomic<bool> cancel{false};
    std::atomic<long> beats{0}; /**< callbacks of the run so far */
  };
  /** A run none of whose callbacks came for this long is taken as hung and ended [s]. */
  static constexpr double kStallS = 120.0;

private:
  void Launch(std::unique_ptr<Job> job);
  void OnThreadDone(std::shared_ptr<const SimResult> r);
  /** On the worker thread: send @p job to the helper process, read its result into @p out. */
  void RunInHelper(Job *job, SimResult *out);
  /** Fork the helper process that runs the jobs (HelperMain); false with @p error. */
  bool StartHelper(QString *error);
  /** End the helper process (SIGKILL) and collect it. */
  void StopHelper();

  std::thread thread_;
  std::unique_ptr<Job> running_;
  std::unique_ptr<Job> queued_;
  bool busy_ = false;
  std::atomic<double> fraction_{0.0};
  std::atomic<bool> cancel_{false};
  std::atomic<bool> hold_next_{false};
  mutable std::mutex sim_mutex_;
  Shared *shared_ = nullptr; /* guarded by sim_mutex_: shared_page_ while a job runs */
  Shared *shared_page_ = nullptr;
  /* the helper process, -1 when there is none (changed by the worker thread after construction) */
  std::atomic<pid_t> helper_pid_{-1};
  int helper_fd_ = -1;    /* its socket */
  QTimer poll_;
};

} // namespace studio

Q_DECLARE_METATYPE(std::shared_ptr<const studio::SimResult>)

#endif
