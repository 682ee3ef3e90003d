#pragma once

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "recognize/recognizer.h"

namespace ecv::test {

/// `model` verified at `pose` as a tracked prior is, by a Recognizer made with `options` (with options.refine:
/// verified, refined by ICP and verified again); the caller lowers min_score and min_visible_fraction to see any
/// score. A test failure and an empty Detection when it is not reported.
inline Detection VerifyPrior(const ModelLibrary& library, const RecognizerOptions& options, const RgbdFrame& frame,
                             const std::string& model, const Eigen::Isometry3d& pose) {
  Detection prior;
  prior.model = model;
  prior.camera_from_object = pose;
  prior.tracked = true;
  prior.score = 1.0;       // followed whatever the bar ...
  prior.confirmed = true;  // ... and not searched for again
  const std::vector<Detection> found = Recognizer(library, options).Recognize(frame, {prior}).detections;
  EXPECT_EQ(found.size(), 1U) << model;
  return found.empty() ? Detection() : found[0];
}

}  // namespace ecv::test
