#include "recognize/acceptance.h"

#include <cmath>
#include <utility>

#include "core/error.h"

namespace ecv {

// recognize/learned_acceptance.json, compiled in (learned_acceptance_json.cpp, made by CMake).
extern const char* const kLearnedAcceptanceJson;

namespace {

using Term = double (*)(const Detection&);

// Each term by name: the detection's JSON field, or derived from it.
const std::vector<std::pair<std::string, Term>>& Terms() {
  static const std::vector<std::pair<std::string, Term>> terms = {
      {"depth_agreement", [](const Detection& d) { return d.depth_agreement; }},
      {"color_agreement", [](const Detection& d) { return d.color_agreement; }},
      {"edge_agreement", [](const Detection& d) { return d.edge_agreement; }},
      {"log_edge_pixels", [](const Detection& d) { return std::log1p(static_cast<double>(d.edge_pixels)); }},
      {"surface_error_mm", [](const Detection& d) { return 1000.0 * d.surface_error_m; }},
      {"contour_agreement", [](const Detection& d) { return d.contour_agreement; }},
      {"continuation", [](const Detection& d) { return d.continuation; }},
      {"visible_fraction", [](const Detection& d) { return d.visible_fraction; }},
      {"inlier_fraction", [](const Detection& d) { return d.inlier_fraction; }},
      {"explained_surface", [](const Detection& d) { return d.explained_surface; }},
      {"free_space_violation", [](const Detection& d) { return d.free_space_violation; }},
      {"occluding_contour", [](const Detection& d) { return d.occluding_contour; }},
      {"creased_contour", [](const Detection& d) { return d.creased_contour; }},
      {"ppf", [](const Detection& d) { return d.hypothesis_source == HypothesisSource::kPpf ? 1.0 : 0.0; }},
  };
  return terms;
}

std::vector<double> Numbers(const nlohmann::json& json, const char* field, size_t count, const std::string& source) {
  const std::string expected = "an array of " + std::to_string(count) + " numbers (one per term)";
  if (!json.contains(field) || !json[field].is_array() || json[field].size() != count) {
    ThrowInputError(source, field, expected);
  }
  std::vector<double> numbers;
  for (const nlohmann::json& value : json[field]) {
    if (!value.is_number() || !std::isfinite(value.get<double>())) ThrowInputError(source, field, expected);
    numbers.push_back(value.get<double>());
  }
  return numbers;
}

double Number(const nlohmann::json& json, const char* field, const std::string& source) {
  if (!json.contains(field) || !json[field].is_number() || !std::isfinite(json[field].get<double>())) {
    ThrowInputError(source, field, "a number");
  }
  return json[field].get<double>();
}

}  // namespace

std::vector<std::string> EvidenceTermNames() {
  std::vector<std::string> names;
  for (const auto& [name, term] : Terms()) names.push_back(name);
  return names;
}

AcceptanceModel AcceptanceModel::FromJson(const nlohmann::json& json, const std::string& source) {
  if (!json.is_object()) ThrowInputError(source, "", "a JSON object (scripts/train_acceptance)");
  if (json.value("kind", "") != "logistic") ThrowInputError(source, "kind", "\"logistic\"");
  if (!json.contains("terms") || !json["terms"].is_array() || json["terms"].empty()) {
    ThrowInputError(source, "terms", "an array of evidence term names");
  }
  AcceptanceModel model;
  for (const nlohmann::json& name : json["terms"]) {
    const auto& terms = Terms();
    const auto found = std::find_if(terms.begin(), terms.end(), [&](const auto& term) {
      return name.is_string() && term.first == name.get<std::string>();
    });
    if (found == terms.end()) ThrowInputError(source, "terms", "names of evidence terms", name.dump());
    model.terms_.push_back(found->second);
  }
  const size_t count = model.terms_.size();
  model.mean_ = Numbers(json, "mean", count, source);
  model.scale_ = Numbers(json, "scale", count, source);
  model.weights_ = Numbers(json, "weights", count, source);
  for (const double scale : model.scale_) {
    if (scale <= 0.0) ThrowInputError(source, "scale", "positive numbers");
  }
  model.bias_ = Number(json, "bias", source);
  model.threshold_ = Number(json, "threshold", source);
  if (model.threshold_ < 0.0 || model.threshold_ > 1.0) ThrowInputError(source, "threshold", "in [0, 1]");
  return model;
}

const AcceptanceModel& AcceptanceModel::Learned() {
  static const AcceptanceModel learned =
      FromJson(nlohmann::json::parse(kLearnedAcceptanceJson), "recognize/learned_acceptance.json");
  return learned;
}

double AcceptanceModel::Probability(const Detection& detection) const {
  double z = bias_;
  for (size_t i = 0; i < terms_.size(); ++i) z += weights_[i] * (terms_[i](detection) - mean_[i]) / scale_[i];
  return 1.0 / (1.0 + std::exp(-z));
}

}  // namespace ecv
