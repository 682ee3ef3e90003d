#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "registration/ppf.h"

namespace ecv {

/// A library model's point pair points (registration/ppf.h): drawn from its mesh when the model is built, stored in
/// the library, made into the point pair table when a recognizer loads. The table itself is not stored: it holds
/// 0.2-6 million pairs per YCB-Video model (1-36 MB), and is made from the points in 20-670 ms.
struct PointPairRecord {
  PpfModelSampling sampling;          ///< how the points were drawn from the mesh
  std::vector<OrientedPoint> points;  ///< object frame, metres, unit normals; empty when refused
  int64_t pairs = 0;                  ///< pairs in the table that PpfOptions' defaults make of them
  std::string refusal;                ///< why the mesh has none (too small, flat or coarse); empty when it has
};

/// The point pair record of `mesh` (object frame, metres): its points, or, when PpfModel refuses them (with
/// `table`'s settings), the refusal without points.
PointPairRecord MakePointPairRecord(const TriangleMesh& mesh, const PpfModelSampling& sampling = {},
                                    const PpfOptions& table = {});

/// The sampling as JSON text, as stored in the library.
std::string PpfSamplingToJson(const PpfModelSampling& sampling);
/// The sampling of JSON text; throws InputError naming `source` and the field for a missing or bad value.
PpfModelSampling PpfSamplingFromJson(const std::string& text, const std::string& source);

/// Points as stored: per point its position and normal, six float32, little-endian.
std::vector<unsigned char> EncodeOrientedPoints(const std::vector<OrientedPoint>& points);
/// Stored points back; throws InputError naming `source` for a size that is not whole points, a value that is not
/// finite or a normal that is not of unit length.
std::vector<OrientedPoint> DecodeOrientedPoints(const unsigned char* data, size_t size, const std::string& source);

}  // namespace ecv
