#pragma once
// The keys of the scene file as navcore_io's one table describes them (nav_schema.h): navstudio's
// forms take each field's unit, scale to SI, bounds and description from here, so a unit or a
// bound changed in the table changes the form too.

#include <QString>

extern "C" {
#include "navcore/nav_schema.h"
}

namespace studio {

/** The table's key at @p path ("imu.gyro.arw_deg_per_sqrt_h"). A path the table does not have is a
 *  programming error (asserted); release builds get a unitless key of scale 1. */
const nav_schema_key &SchemaKey(const char *path);

/** A unit as the table writes it ("deg/sqrt(h)", "ug", "m/s^2") for display ("deg/√h", "µg",
 *  "m/s²"); "1" (dimensionless) shows as nothing. */
QString DisplayUnit(const char *unit);

/** A field's tooltip line from the table: description, accepted range, default. */
QString KeyHelp(const nav_schema_key &k);

} // namespace studio
