#include "modeldb/point_pair_record.h"

#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace ecv {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "point pair points are stored as little-endian float32");

constexpr size_t kPointBytes = 6 * sizeof(float);

}  // namespace

PointPairRecord MakePointPairRecord(const TriangleMesh& mesh, const PpfModelSampling& sampling,
                                    const PpfOptions& table) {
  PointPairRecord record;
  record.sampling = sampling;
  try {
    PpfOptions options = table;
    options.sampling = sampling.sampling;
    options.keep_normal_deg = sampling.keep_normal_deg;
    const PpfModel model = PpfModel::FromSampledPoints(SampleModelPoints(mesh, sampling), mesh.Diameter(), options);
    record.points = model.points();
    record.pairs = static_cast<int64_t>(model.NumPairs());
  } catch (const InputError& error) {
    record.refusal = error.what();
  }
  return record;
}

std::string PpfSamplingToJson(const PpfModelSampling& sampling) {
  return nlohmann::json{
      {"samples", sampling.samples}, {"sampling", sampling.sampling}, {"keep_normal_deg", sampling.keep_normal_deg}}
      .dump();
}

PpfModelSampling PpfSamplingFromJson(const std::string& text, const std::string& source) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (!json.is_object()) ThrowInputError(source, "point pair settings", "a JSON object", text.substr(0, 80));
  auto number = [&](const char* key) {
    const auto found = json.find(key);
    if (found == json.end() || !found->is_number()) ThrowInputError(source, key, "a number");
    return found->get<double>();
  };
  PpfModelSampling sampling;
  const double samples = number("samples");
  if (!(samples >= 1.0 && samples <= 1e9 && samples == std::floor(samples)))
    ThrowInputError(source, "samples", "a whole number of points", std::to_string(samples));
  sampling.samples = static_cast<int>(samples);
  sampling.sampling = number("sampling");
  sampling.keep_normal_deg = number("keep_normal_deg");
  try {
    sampling.Check();
  } catch (const InputError& error) {
    throw InputError(source + ": " + error.what());
  }
  return sampling;
}

std::vector<unsigned char> EncodeOrientedPoints(const std::vector<OrientedPoint>& points) {
  std::vector<unsigned char> bytes(points.size() * kPointBytes);
  for (size_t i = 0; i < points.size(); ++i) {
    const float values[6] = {points[i].position.x(), points[i].position.y(), points[i].position.z(),
                             points[i].normal.x(),   points[i].normal.y(),   points[i].normal.z()};
    std::memcpy(bytes.data() + i * kPointBytes, values, kPointBytes);
  }
  return bytes;
}

std::vector<OrientedPoint> DecodeOrientedPoints(const unsigned char* data, size_t size, const std::string& source) {
  if (size % kPointBytes != 0) {
    ThrowInputError(source, "point pair points", "whole points of 24 bytes", std::to_string(size) + " bytes");
  }
  std::vector<OrientedPoint> points(size / kPointBytes);
  for (size_t i = 0; i < points.size(); ++i) {
    float values[6];
    std::memcpy(values, data + i * kPointBytes, kPointBytes);
    for (const float value : values) {
      if (!std::isfinite(value))
        ThrowInputError(source, "point pair point " + std::to_string(i), "finite values", "not finite");
    }
    points[i].position = {values[0], values[1], values[2]};
    points[i].normal = {values[3], values[4], values[5]};
    if (std::abs(points[i].normal.norm() - 1.0F) > 1e-3F)
      ThrowInputError(source, "point pair point " + std::to_string(i), "a unit normal",
                      "length " + std::to_string(points[i].normal.norm()));
  }
  return points;
}

}  // namespace ecv
