#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <stdexcept>
#include <vector>

namespace scanplan {

class ImageCodecError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

std::vector<std::uint8_t> encode_jpeg(const cv::Mat& bgr, int quality = 90);
// Decodes JPEG or PNG into 8-bit BGR; throws ImageCodecError for bytes that are no image.
cv::Mat decode_image(std::span<const std::uint8_t> bytes);

}  // namespace scanplan
