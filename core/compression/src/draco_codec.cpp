#include "scanplan/compression/draco_codec.hpp"

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/point_cloud/point_cloud_builder.h>

#include <cstdint>
#include <limits>

namespace scanplan {

std::string encode_draco(const PointCloud& cloud, const DracoOptions& options) {
  return encode_draco(std::vector<const PointCloud*>{&cloud}, options);
}

std::string encode_draco(const std::vector<const PointCloud*>& parts, const DracoOptions& options) {
  std::size_t total = 0;
  bool colored = true;
  for (const PointCloud* part : parts) {
    total += part->size();
    colored = colored && (part->empty() || part->has_colors());  // as PointCloud::append
  }
  if (total == 0) throw DracoError("cannot encode an empty point cloud");
  if (total > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    throw DracoError("too many points for one Draco point cloud: " + std::to_string(total));
  }
  draco::PointCloudBuilder builder;
  builder.Start(static_cast<draco::PointIndex::ValueType>(total));
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int col =
      colored ? builder.AddAttribute(draco::GeometryAttribute::COLOR, 3, draco::DT_UINT8) : -1;
  std::unique_ptr<draco::PointCloud> pc = builder.Finalize(false);
  if (!pc) throw DracoError("draco could not build the point cloud");
  // Each part's values in one copy per attribute (both are packed: 12 and 3 bytes a point).
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float) && sizeof(Rgb) == 3);
  std::int64_t at = 0;
  for (const PointCloud* part : parts) {
    pc->attribute(pos)->buffer()->Write(at * static_cast<std::int64_t>(sizeof(Eigen::Vector3f)),
                                        part->points.data(),
                                        part->size() * sizeof(Eigen::Vector3f));
    if (col >= 0) {
      pc->attribute(col)->buffer()->Write(at * static_cast<std::int64_t>(sizeof(Rgb)),
                                          part->colors.data(), part->size() * sizeof(Rgb));
    }
    at += static_cast<std::int64_t>(part->size());
  }
  if (col >= 0) pc->attribute(col)->set_normalized(true);

  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, options.position_bits);
  encoder.SetSpeedOptions(options.encode_speed, options.decode_speed);
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodePointCloudToBuffer(*pc, &buffer);
  if (!status.ok()) throw DracoError("draco encoding failed: " + status.error_msg_string());
  return std::string(buffer.data(), buffer.size());
}

PointCloud decode_draco(std::string_view bytes) {
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  auto result = decoder.DecodePointCloudFromBuffer(&buffer);
  if (!result.ok())
    throw DracoError("not a Draco point cloud: " + result.status().error_msg_string());
  const std::unique_ptr<draco::PointCloud> pc = std::move(result).value();
  const draco::PointAttribute* pos = pc->GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (!pos || pos->num_components() != 3) throw DracoError("the Draco data has no 3-D positions");
  const draco::PointAttribute* col = pc->GetNamedAttribute(draco::GeometryAttribute::COLOR);
  if (col && col->num_components() < 3) col = nullptr;

  PointCloud cloud;
  const std::size_t n = pc->num_points();
  cloud.points.resize(n);
  if (col) cloud.colors.resize(n);
  for (draco::PointIndex i(0); i < pc->num_points(); ++i) {
    pos->ConvertValue<float, 3>(pos->mapped_index(i), cloud.points[i.value()].data());
    if (col) {
      // Read as integers so a normalised uint8 attribute keeps 0..255 here.
      std::array<std::uint8_t, 4> c{};
      col->ConvertValue<std::uint8_t>(col->mapped_index(i), 3, c.data());
      cloud.colors[i.value()] = {c[0], c[1], c[2]};
    }
  }
  return cloud;
}

}  // namespace scanplan
