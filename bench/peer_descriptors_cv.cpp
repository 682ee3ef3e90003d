// OpenCV's SIFT and ORB, at given keypoints or at their own, lifted to 3D with the depth image.

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "ecv/surface.h"
#include "peer_descriptors_cv.h"

namespace ecv::bench {
namespace {

cv::Ptr<cv::Feature2D> Make(ImageDescriptor descriptor) {
  if (descriptor == ImageDescriptor::kSift) return cv::SIFT::create();
  return cv::ORB::create(3000);
}

// 3D positions of keypoints from the depth image; keypoints without depth are dropped.
KeypointDescriptors Lift(const RgbdFrame& frame, const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& values,
                         bool binary) {
  KeypointDescriptors out;
  out.binary = binary;
  std::vector<int> rows;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const cv::Point pixel(cvRound(keypoints[i].pt.x), cvRound(keypoints[i].pt.y));
    const std::optional<float> z = FrontSurfaceDepth(frame.depth, pixel, 0.01);
    if (!z) continue;
    out.positions.push_back(
        frame.camera.BackProject(Eigen::Vector2d(keypoints[i].pt.x, keypoints[i].pt.y), *z).cast<float>());
    rows.push_back(static_cast<int>(i));
  }
  out.values.create(static_cast<int>(rows.size()), values.cols, values.type());
  for (size_t i = 0; i < rows.size(); ++i) values.row(rows[i]).copyTo(out.values.row(static_cast<int>(i)));
  out.valid.assign(rows.size(), true);
  return out;
}

}  // namespace

const char* ToString(ImageDescriptor descriptor) {
  return descriptor == ImageDescriptor::kSift ? "SIFT" : "ORB";
}

KeypointDescriptors ComputeImageDescriptorsAt(const RgbdFrame& frame, const std::vector<Primitive>& primitives,
                                              ImageDescriptor descriptor, float size_px) {
  cv::Mat grey;
  cv::cvtColor(frame.color, grey, cv::COLOR_RGB2GRAY);
  std::vector<cv::KeyPoint> keypoints;
  for (size_t i = 0; i < primitives.size(); ++i) {
    const Primitive& p = primitives[i];
    // The monogenic orientation as the keypoint's angle: rotation-covariant like SIFT's own.
    keypoints.emplace_back(cv::Point2f(p.pixel.x(), p.pixel.y()), size_px,
                           static_cast<float>(p.image_orientation * 180.0 / M_PI), 0.0F, 0, static_cast<int>(i));
  }
  cv::Mat values;
  Make(descriptor)->compute(grey, keypoints, values);
  // compute() drops keypoints too near the border; class_id still names the primitive.
  KeypointDescriptors out;
  out.binary = descriptor == ImageDescriptor::kOrb;
  out.positions.resize(primitives.size());
  for (size_t i = 0; i < primitives.size(); ++i) out.positions[i] = primitives[i].position;
  out.values = cv::Mat::zeros(static_cast<int>(primitives.size()), values.cols, values.type());
  out.valid.assign(primitives.size(), false);
  for (size_t k = 0; k < keypoints.size(); ++k) {
    const int i = keypoints[k].class_id;
    values.row(static_cast<int>(k)).copyTo(out.values.row(i));
    out.valid[static_cast<size_t>(i)] = true;
  }
  return out;
}

KeypointDescriptors ComputeImageDescriptorsOwn(const RgbdFrame& frame, const cv::Mat& mask,
                                               ImageDescriptor descriptor) {
  cv::Mat grey;
  cv::cvtColor(frame.color, grey, cv::COLOR_RGB2GRAY);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat values;
  Make(descriptor)->detectAndCompute(grey, mask, keypoints, values);
  return Lift(frame, keypoints, values, descriptor == ImageDescriptor::kOrb);
}

}  // namespace ecv::bench
