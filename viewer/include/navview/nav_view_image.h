/**
 * @file nav_view_image.h
 * @brief PNG regression comparison for the render tests (vtkImageDifference behind a plain API).
 */
#ifndef NAV_VIEW_IMAGE_H
#define NAV_VIEW_IMAGE_H

#include <string>

/** Outcome of comparing a rendered image with its baseline. */
struct NavImageComparison {
  bool baseline_found = false;
  bool size_matches = false;
  double thresholded_error = 0.0; /**< vtkImageDifference::GetThresholdedError() */
  int width_px = 0, height_px = 0;
};

/**
 * Compare the PNG @p actual_png with @p baseline_png using vtkImageDifference (which tolerates
 * one-pixel shifts; pixels count when their summed R, G, B difference exceeds 40 of 765) and
 * return whether the thresholded error is at most @p threshold.
 * When they differ (or the baseline is missing) and @p diff_png is not empty, the difference
 * image is written there.
 */
bool NavCompareImages(const std::string &actual_png, const std::string &baseline_png, double threshold,
                      const std::string &diff_png, NavImageComparison *out, std::string *error);

#endif /* NAV_VIEW_IMAGE_H */
