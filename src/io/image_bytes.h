#pragma once

// Images held in memory, as a request carries them: base64 text and PNG bytes, checked and converted as the file
// readers of io/frame_io.h convert theirs (which use the same conversions).

#include <array>
#include <string>

#include <opencv2/core.hpp>

#include "core/frame.h"

namespace ecv {

/// The largest width and height, pixels, of an image decoded from bytes: checked in the PNG header before decoding.
constexpr int kMaxDecodedSide = 8192;

/// The bytes that base64 `text` (RFC 4648, with padding; no line breaks) spells. Throws InputError "<source>:
/// <field>: expected base64 ..." on any other character, a bad length or misplaced padding.
std::string DecodeBase64(const std::string& text, const std::string& source, const std::string& field);

/// An 8-bit grey, RGB or RGBA PNG file's bytes as CV_8UC3 RGB. Throws InputError naming `source` for bytes that are
/// not a PNG, a PNG larger than kMaxDecodedSide a side (before decoding it) or of another type.
cv::Mat DecodeColorPng(const std::string& bytes, const std::string& source);

/// A 16-bit single-channel PNG file's bytes to CV_32FC1 metres (value / `depth_scale`, 0 stays missing); errors as
/// DecodeColorPng's, and for a scale that is not finite and positive.
cv::Mat DecodeDepthPng(const std::string& bytes, double depth_scale, const std::string& source);

/// A decoded colour image (8-bit grey, BGR or BGRA, as OpenCV decodes) as CV_8UC3 RGB; InputError naming `source` for
/// other types.
cv::Mat ColorImageAsRgb(const cv::Mat& decoded, const std::string& source);

/// InputError naming `source` unless `depth_scale` (depth values per metre) is finite and positive.
void CheckDepthScale(double depth_scale, const std::string& source);

/// A decoded 16-bit single-channel depth image as CV_32FC1 metres (value / `depth_scale`); InputError naming
/// `source` for other types.
cv::Mat DepthImageAsMetres(const cv::Mat& decoded, double depth_scale, const std::string& source);

/// A frame of a colour image (CV_8UC3 RGB) and a depth image (CV_32FC1 metres) of one size, seen by a camera of
/// intrinsics {fx, fy, cx, cy} in pixels; InputError naming `depth_source` for a size that differs from the colour
/// image's (`color_source`), and RgbdFrame::Check's. `name` names the frame.
RgbdFrame FrameOfImages(const cv::Mat& color, const cv::Mat& depth, const std::array<double, 4>& intrinsics,
                        const std::string& color_source, const std::string& depth_source, const std::string& name);

}  // namespace ecv
