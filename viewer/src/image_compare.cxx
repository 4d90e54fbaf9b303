// PNG regression comparison (nav_view_image.h) with vtkImageDifference, as VTK's own tests do.
#include "navview/nav_view_image.h"

#include <sys/stat.h>

#include <vtkImageData.h>
#include <vtkImageDifference.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPNGWriter.h>

namespace {
bool Exists(const std::string &p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}
} // namespace

bool NavCompareImages(const std::string &actual_png, const std::string &baseline_png, double threshold,
                      const std::string &diff_png, NavImageComparison *out, std::string *error) {
  *out = NavImageComparison();
  if (!Exists(actual_png)) {
    *error = actual_png + ": error: rendered image not found";
    return false;
  }
  vtkNew<vtkPNGReader> actual;
  actual->SetFileName(actual_png.c_str());
  actual->Update();
  int da[3];
  actual->GetOutput()->GetDimensions(da);
  out->width_px = da[0];
  out->height_px = da[1];
  if (!Exists(baseline_png)) {
    *error = baseline_png + ": error: baseline missing";
    return false;
  }
  out->baseline_found = true;
  vtkNew<vtkPNGReader> base;
  base->SetFileName(baseline_png.c_str());
  base->Update();
  int db[3];
  base->GetOutput()->GetDimensions(db);
  if (da[0] != db[0] || da[1] != db[1] ||
      actual->GetOutput()->GetNumberOfScalarComponents() !=
          base->GetOutput()->GetNumberOfScalarComponents()) {
    *error = "image size or channels differ: rendered " + std::to_string(da[0]) + "x" +
             std::to_string(da[1]) + ", baseline " + std::to_string(db[0]) + "x" + std::to_string(db[1]);
    return false;
  }
  out->size_matches = true;
  vtkNew<vtkImageDifference> diff;
  diff->SetInputConnection(actual->GetOutputPort());
  diff->SetImageConnection(base->GetOutputPort());
  // Per-pixel tolerance (sum of the R, G, B differences) before a pixel counts; VTK's default
  // of 105 ignores whole colour changes of thin lines. One-pixel shifts stay allowed.
  diff->SetThreshold(40);
  diff->Update();
  out->thresholded_error = diff->GetThresholdedError();
  const bool ok = out->thresholded_error <= threshold;
  if (!ok) {
    *error = "thresholded image error " + std::to_string(out->thresholded_error) + " exceeds " +
             std::to_string(threshold);
    if (!diff_png.empty()) {
      vtkNew<vtkPNGWriter> w;
      w->SetFileName(diff_png.c_str());
      w->SetInputConnection(diff->GetOutputPort());
      w->Write();
    }
  }
  return ok;
}
