#pragma once

// Helpers of the model-database tests: synthetic models (no rendering), a library in the prototype layout
// (schema version 0) written by hand, and comparisons bit for bit.

#include <cstdint>
#include <string>
#include <vector>

#include "modeldb/model_record.h"

namespace ecv::test {

/// A model of `views` views with `primitives` random primitives each (seeded); every 5th primitive has no
/// descriptor, the others random 96-float descriptors.
ModelRecord SyntheticModel(const std::string& name, int views, int primitives, uint32_t seed);

/// Writes a library in the prototype layout (user_version 0, a `settings` table, models without the columns
/// that version 1 added) holding `models`, with SQL written here by hand, not by the library.
void WritePrototypeLibrary(const std::string& path, const std::vector<ModelRecord>& models);

/// Empty when equal bit for bit (cameras, poses, every primitive field, descriptor rows and values);
/// otherwise what differs first.
std::string CompareViews(const std::vector<ModelView>& expected, const std::vector<ModelView>& actual);

/// Half the YCB-Video camera (320x240), so that tests render and describe quickly.
PinholeCamera SmallCamera();

/// The demo meshes in models/meshes.
std::string DemoMeshDirectory();

}  // namespace ecv::test
