// navstudio report export (report_export.h).
#include "report_export.h"

#include <QBuffer>
#include <QByteArray>
#include <QDateTime>
#include <QSaveFile>
#include <cmath>

#include "navcore/nav_math.h"
#include "navcore/nav_requirements.h"

namespace studio {

namespace {

QString Esc(const QString &s) { return s.toHtmlEscaped(); }

QString Num(double v, int digits = 4) {
  return std::isfinite(v) ? QString::number(v, 'g', digits) : QStringLiteral("&ndash;");
}

QString StatRow(const QString &name, const nav_stat &s, double scale, const QString &unit) {
  return QString("<tr><td>%1</td><td>%2</td><td>%3</td><td>%4</td><td>%5</td></tr>\n")
      .arg(Esc(name), Num(s.rms * scale), Num(s.p95 * scale), Num(s.max * scale), Esc(unit));
}

} // namespace

QString StudioReportHtml(const StudioReport &r) {
  QString h;
  h += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n";
  h += "<title>navstudio report: " + Esc(r.scene_name) + "</title>\n";
  h += "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#111}"
       "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:4px 10px;text-align:right}"
       "th{background:#eee}td:first-child,th:first-child{text-align:left}.pass{color:#06702a;font-weight:bold}"
       ".fail{color:#b00020;font-weight:bold}pre{background:#f6f6f6;padding:1em;overflow:auto}"
       "figure{margin:1.5em 0}img{max-width:100%;border:1px solid #ccc}</style></head><body>\n";
  h += "<h1>navstudio report: " + Esc(r.scene_name) + "</h1>\n";
  h += "<p>Scene: " + (r.scene_path.isEmpty() ? QString("(not saved)") : Esc(r.scene_path)) + "<br>IMU: " +
       Esc(r.imu.isEmpty() ? QString("custom terms") : r.imu) +
       "<br>GNSS receiver: " + Esc(r.receiver.isEmpty() ? QString("custom terms") : r.receiver) +
       "<br>Written " + Esc(QDateTime::currentDateTimeUtc().toString(Qt::ISODate)) + "</p>\n";
  const SimResult *res = r.result;
  if (!res) {
    h += "<p><b>No simulation has been run for this scene yet.</b></p>\n";
  } else {
    h += QString("<h2>Result</h2>\n<p>%1 Monte Carlo run%2, %3 s wall%4.</p>\n")
             .arg(res->summary.runs)
             .arg(res->summary.runs == 1 ? "" : "s")
             .arg(Num(res->wall_s, 3))
             .arg(res->summary.partial ? " &ndash; <b>stopped early: partial result</b>" : "");
    if (!res->verdicts.empty()) {
      long passed = 0;
      for (const auto &v : res->verdicts) passed += v.pass ? 1 : 0;
      h += QString("<h2>Requirements: %1 of %2 pass</h2>\n").arg(passed).arg(res->verdicts.size());
      h += "<table><tr><th>requirement</th><th>metric</th><th>statistic</th><th>value</th><th>limit</th>"
           "<th>unit</th><th>verdict</th></tr>\n";
      for (const auto &v : res->verdicts)
        h += QString("<tr><td>%1</td><td>%2</td><td>%3</td><td>%4</td><td>%5</td><td>%6</td>"
                     "<td class=\"%7\">%8</td></tr>\n")
                 .arg(Esc(QString::fromUtf8(v.id)), Esc(nav_req_metric_name(v.metric)),
                      Esc(nav_req_statistic_name(v.statistic)), Num(v.value), Num(v.limit),
                      Esc(nav_req_unit_name(v.unit)), v.pass ? "pass" : "fail",
                      v.pass ? (v.evaluated ? "PASS" : "PASS (nothing to evaluate)") : "FAIL");
      h += "</table>\n";
    }
    const nav_sim_stats &s = res->summary.stats;
    h += "<h2>Errors over all runs and epochs</h2>\n<table><tr><th>error</th><th>RMS</th><th>95 %</th>"
         "<th>max</th><th>unit</th></tr>\n";
    h += StatRow("horizontal position", s.pos_err_h_m, 1.0, "m");
    h += StatRow("vertical position", s.pos_err_v_m, 1.0, "m");
    h += StatRow("velocity", s.vel_err_mps, 1.0, "m/s");
    h += StatRow("attitude", s.att_err_rad, NAV_RAD2DEG, "deg");
    h += StatRow("yaw", s.yaw_err_rad, NAV_RAD2DEG, "deg");
    h += "</table>\n";
    h += QString("<p>Horizontal error at the end (%1 s): run 0 %2 m, RMS over the runs %3 m.</p>\n")
             .arg(Num(res->summary.duration_s, 5), Num(res->summary.final.pos_err_h_m),
                  Num(res->summary.final_rms.pos_err_h_m));
  }

  for (const auto &im : r.images) {
    if (im.second.isNull()) continue;
    QByteArray png;
    QBuffer buf(&png);
    buf.open(QIODevice::WriteOnly);
    im.second.save(&buf, "PNG");
    h += "<figure><img alt=\"" + Esc(im.first) + "\" src=\"data:image/png;base64," +
         QString::fromLatin1(png.toBase64()) + "\"><figcaption>" + Esc(im.first) + "</figcaption></figure>\n";
  }
  h += "</body></html>\n";
  return h;
}

bool WriteStudioReport(const QString &path, const StudioReport &report, QString *error) {
  QSaveFile f(path); // writes a temporary file and renames it on commit()
  if (!f.open(QIODevice::WriteOnly)) {
    if (error) *error = QString("%1: %2").arg(path, f.errorString());
    return false;
  }
  const QByteArray html = StudioReportHtml(report).toUtf8();
  if (f.write(html) != html.size() || !f.commit()) {
    if (error) *error = QString("%1: %2").arg(path, f.errorString());
    return false;
  }
  return true;
}

} // namespace studio
