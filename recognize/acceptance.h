#pragma once

// A learned acceptance: the probability that a verified pose is right, from its evidence (scripts/train_acceptance).

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "recognize/detection.h"

namespace ecv {

/// A logistic model over a pose's evidence terms: P(right) = 1 / (1 + exp(-(bias + sum_i w_i (x_i - mean_i) /
/// scale_i))); a pose is accepted from `threshold` on.
class AcceptanceModel {
 public:
  /// The model of scripts/train_acceptance's JSON; throws InputError naming `source` and the field when a field is
  /// missing or malformed, or names an unknown term.
  static AcceptanceModel FromJson(const nlohmann::json& json, const std::string& source);
  /// The model trained on the generalisation set's choosing half that ships with ecvpose
  /// (recognize/learned_acceptance.json, built in).
  static const AcceptanceModel& Learned();

  double Probability(const Detection& detection) const;
  double threshold() const { return threshold_; }

 private:
  using Term = double (*)(const Detection&);
  std::vector<Term> terms_;
  std::vector<double> mean_, scale_, weights_;
  double bias_ = 0.0;
  double threshold_ = 0.5;
};

/// The names of the evidence terms a model may weigh, as scripts/train_acceptance's TERMS.
std::vector<std::string> EvidenceTermNames();

}  // namespace ecv
