#include "scanplan/io/image_codec.hpp"

#include <opencv2/imgcodecs.hpp>

namespace scanplan {

std::vector<std::uint8_t> encode_jpeg(const cv::Mat& bgr, int quality) {
  std::vector<std::uint8_t> out;
  if (!cv::imencode(".jpg", bgr, out, {cv::IMWRITE_JPEG_QUALITY, quality})) {
    throw ImageCodecError("JPEG encoding failed");
  }
  return out;
}

cv::Mat decode_image(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) throw ImageCodecError("the image is empty");
  // imdecode wants a Mat header; it only reads through it.
  const cv::Mat raw(1, static_cast<int>(bytes.size()), CV_8UC1,
                    const_cast<std::uint8_t*>(bytes.data()));
  cv::Mat img = cv::imdecode(raw, cv::IMREAD_COLOR);
  if (img.empty()) throw ImageCodecError("the image bytes are not a JPEG or PNG OpenCV can read");
  return img;
}

}  // namespace scanplan
