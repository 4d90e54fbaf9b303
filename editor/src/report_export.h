// navstudio: the report of a result as one self-contained HTML file (File > Export report...).
#pragma once

#include <QImage>
#include <QString>
#include <vector>

#include "sim_worker.h"

namespace studio {

/** What the report shows: the scene, the result of the last full run and pictures of the views. */
struct StudioReport {
  QString scene_name;
  QString scene_path;     /**< "" for an unsaved scene */
  QString imu, receiver;  /**< catalog names as chosen ("" for custom terms) */
  const SimResult *result = nullptr; /**< may be NULL: no run yet (the report says so) */
  std::vector<std::pair<QString, QImage>> images; /**< caption, picture (PNG-embedded) */
};

/** The report as HTML: title, scene, verdicts table (PASS/FAIL per requirement with value and
 *  limit in the user's units), statistics over runs and epochs, the final error, the pictures as
 *  data: URIs. Text is HTML-escaped. */
QString StudioReportHtml(const StudioReport &report);

/** Write StudioReportHtml() to @p path atomically (temporary file in the same directory, then
 *  rename). @return false with @p error on failure; an existing file is then left unchanged. */
bool WriteStudioReport(const QString &path, const StudioReport &report, QString *error);

} // namespace studio
