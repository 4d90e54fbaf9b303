/**
 * @file navview.h
 * @brief Umbrella header of libnavview: result loading, display decimation, the render-frame
 *        adapter, the 3D scene, the error charts and PNG comparison. No VTK types.
 */
#ifndef NAVVIEW_H
#define NAVVIEW_H

#include "navview/nav_view_chart.h"
#include "navview/nav_view_decimate.h"
#include "navview/nav_view_frame.h"
#include "navview/nav_view_image.h"
#include "navview/nav_view_map.h"
#include "navview/nav_view_model.h"
#include "navview/nav_view_result.h"
#include "navview/nav_view_scene.h"

#endif /* NAVVIEW_H */
