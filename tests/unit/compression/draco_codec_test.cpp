#include <gtest/gtest.h>

#include <random>

#include "scanplan/compression/draco_codec.hpp"

namespace scanplan {
namespace {

PointCloud random_cloud(std::size_t n, float extent, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent / 2, extent / 2);
  std::uniform_int_distribution<int> c(0, 255);
  PointCloud cloud;
  for (std::size_t i = 0; i < n; ++i) {
    cloud.push_back({u(rng), u(rng), u(rng) / 10},
                    {std::uint8_t(c(rng)), std::uint8_t(c(rng)), std::uint8_t(c(rng))});
  }
  return cloud;
}

// Draco may reorder points (kd-tree encoder), so compare as multisets: sort both by position.
void sort_cloud(PointCloud& cloud) {
  std::vector<std::size_t> idx(cloud.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    const auto& p = cloud.points[a];
    const auto& q = cloud.points[b];
    return std::tie(p.x(), p.y(), p.z()) < std::tie(q.x(), q.y(), q.z());
  });
  PointCloud sorted;
  for (std::size_t i : idx) sorted.push_back(cloud.points[i], cloud.colors[i]);
  cloud = std::move(sorted);
}

struct RoundTripCase {
  std::size_t points;
  float extent_m;
  int bits;
};

class DracoRoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(DracoRoundTrip, PositionsWithinQuantisationAndColoursExact) {
  const auto [n, extent, bits] = GetParam();
  const PointCloud in = random_cloud(n, extent, 42);
  DracoOptions options;
  options.position_bits = bits;
  const std::string bytes = encode_draco(in, options);
  // Header overhead dominates tiny clouds; from a thousand points on Draco must beat raw
  // float xyz + rgb8 (15 bytes a point).
  if (n >= 1000) {
    EXPECT_LT(bytes.size(), n * 15);
  }

  PointCloud out = decode_draco(bytes);
  ASSERT_EQ(out.size(), in.size());
  ASSERT_TRUE(out.has_colors());

  // Quantisation spans the largest extent with 2^bits levels: half a step is the worst error.
  const float tolerance = extent / float((1 << bits) - 1) * 0.5f + 1e-5f;
  PointCloud expected = in;
  // Sorting by quantised x can differ from sorting by exact x for near-ties, so match each
  // decoded point against its nearest original after sorting both on a coarse key.
  sort_cloud(expected);
  sort_cloud(out);
  std::size_t exact_colour = 0;
  float worst = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    float best = std::numeric_limits<float>::max();
    std::size_t best_j = i;
    for (std::size_t j = (i > 8 ? i - 8 : 0); j < std::min(out.size(), i + 9); ++j) {
      const float d = (out.points[i] - expected.points[j]).cwiseAbs().maxCoeff();
      if (d < best) best = d, best_j = j;
    }
    worst = std::max(worst, best);
    exact_colour += out.colors[i] == expected.colors[best_j];
  }
  EXPECT_LE(worst, tolerance);
  EXPECT_EQ(exact_colour, out.size());
}

INSTANTIATE_TEST_SUITE_P(Sizes, DracoRoundTrip,
                         ::testing::Values(RoundTripCase{1, 1.0f, 11},
                                           RoundTripCase{1000, 12.0f, 11},
                                           RoundTripCase{20000, 200.0f, 14}));

TEST(DracoCodec, EmptyCloudIsRefused) {
  EXPECT_THROW(encode_draco(PointCloud{}), DracoError);
}

TEST(DracoCodec, GarbageIsRefusedWithMessage) {
  try {
    decode_draco("definitely not draco");
    FAIL() << "decoding garbage must throw";
  } catch (const DracoError& e) {
    EXPECT_NE(std::string(e.what()).find("not a Draco point cloud"), std::string::npos);
  }
}

TEST(DracoCodec, CloudWithoutColoursDecodesWithoutColours) {
  PointCloud in = random_cloud(100, 5, 1);
  in.colors.clear();
  const PointCloud out = decode_draco(encode_draco(in));
  EXPECT_EQ(out.size(), 100u);
  EXPECT_FALSE(out.has_colors());
}

// The whole map is encoded from the scans' clouds as they are (no copy of the map first): the
// same bytes as the clouds appended into one.
TEST(DracoCodec, PartsEncodeAsTheirConcatenation) {
  const PointCloud a = random_cloud(3000, 80, 2), b = random_cloud(5000, 120, 3);
  const PointCloud empty;
  PointCloud both = a;
  both.append(b);
  EXPECT_TRUE(encode_draco(std::vector<const PointCloud*>{&a, &empty, &b}) == encode_draco(both))
      << "the same bytes as the parts appended into one";

  // One part without colours: none are encoded.
  PointCloud grey = random_cloud(100, 5, 4);
  grey.colors.clear();
  const PointCloud out = decode_draco(encode_draco(std::vector<const PointCloud*>{&a, &grey}));
  EXPECT_EQ(out.size(), a.size() + grey.size());
  EXPECT_FALSE(out.has_colors());
  EXPECT_THROW(encode_draco(std::vector<const PointCloud*>{&empty}), DracoError);
}

}  // namespace
}  // namespace scanplan
