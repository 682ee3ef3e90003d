#pragma once

// Images as bytes: base64 text and PNG bytes as a request carries them, and the image files every reader decodes,
// their size checked in the header first (io/image_header.h); the conversions the readers of io/frame_io.h share.

#include <array>
#include <cstddef>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/frame.h"

namespace ecv {

/// The largest width and height, pixels, of an image decoded from bytes or a file: checked in its header before
/// decoding, so that no image takes more than kMaxDecodedBytes (a 16-bit RGBA image of this size).
constexpr int kMaxDecodedSide = 8192;
constexpr size_t kMaxDecodedBytes = size_t{kMaxDecodedSide} * kMaxDecodedSide * 8;
/// The largest image file read: an uncompressed image of kMaxDecodedBytes.
constexpr size_t kMaxImageFileBytes = kMaxDecodedBytes + (size_t{1} << 20);

/// The bytes that base64 `text` (RFC 4648, with padding; no line breaks) spells. Throws InputError "<source>:
/// <field>: expected base64 ..." on any other character, a bad length or misplaced padding.
std::string DecodeBase64(const std::string& text, const std::string& source, const std::string& field);

/// The bytes of a PNG, JPG or TIFF file decoded by cv::imdecode with `flags`, after its header has been checked
/// (io/image_header.h): 1 to kMaxDecodedSide pixels a side, at most kMaxDecodedBytes decoded. Throws InputError
/// "<source>: <what>: expected a PNG of 1 to 8192 pixels a side, got 20000 x 20000" and the like, for other bytes and
/// for bytes that do not decode.
cv::Mat DecodeImage(const std::string& bytes, const std::string& source, const std::string& what,
                    int flags = cv::IMREAD_UNCHANGED);

/// The image file `path` (a regular file of at most kMaxImageFileBytes) decoded as DecodeImage does; InputError naming
/// `path` and `what` otherwise.
cv::Mat ReadImageFile(const std::string& path, const std::string& what, int flags = cv::IMREAD_UNCHANGED);

/// An 8-bit grey, RGB or RGBA PNG file's bytes as CV_8UC3 RGB. Throws InputError naming `source` for bytes that are
/// not a PNG, a PNG larger than kMaxDecodedSide a side (before decoding it) or of another type.
cv::Mat DecodeColorPng(const std::string& bytes, const std::string& source);

/// A 16-bit single-channel PNG file's bytes to CV_32FC1 metres (value / `depth_scale`, 0 stays missing); errors as
/// DecodeColorPng's, and for a scale that is not finite and positive.
cv::Mat DecodeDepthPng(const std::string& bytes, double depth_scale, const std::string& source);

/// A decoded colour image (8-bit grey, BGR or BGRA, as OpenCV decodes) as CV_8UC3 RGB; InputError naming `source` for
/// other types.
cv::Mat ColorImageAsRgb(const cv::Mat& decoded, const std::string& source);

/// InputError naming `source` and `field` (the file and key that hold it) unless `depth_scale` (depth values per
/// metre) is finite and positive.
void CheckDepthScale(double depth_scale, const std::string& source, const std::string& field = "depth_scale");

/// InputError naming `source` and `field` (the file and key that hold them) unless the intrinsics {fx, fy, cx, cy}
/// (pixels) have fx and fy finite and positive, cx and cy finite.
void CheckIntrinsics(const std::array<double, 4>& intrinsics, const std::string& source, const std::string& field);

/// A decoded 16-bit single-channel depth image as CV_32FC1 metres (value / `depth_scale`); InputError naming
/// `source` for other types.
cv::Mat DepthImageAsMetres(const cv::Mat& decoded, double depth_scale, const std::string& source);

/// A frame of a colour image (CV_8UC3 RGB) and a depth image (CV_32FC1 metres) of one size, seen by a camera of
/// intrinsics {fx, fy, cx, cy} in pixels. `name` names the frame (the file that pairs the images, or the request):
/// InputError naming it, `color_source` and `depth_source` for images of two sizes, and RgbdFrame::Check's.
RgbdFrame FrameOfImages(const cv::Mat& color, const cv::Mat& depth, const std::array<double, 4>& intrinsics,
                        const std::string& color_source, const std::string& depth_source, const std::string& name);

}  // namespace ecv
