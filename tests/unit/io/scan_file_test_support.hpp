#pragma once

// Helpers shared by the tests of the point-cloud file readers (PLY, PCD, 3DTK) and of the
// replay folder that lists such files.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <system_error>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/io/scan_file.hpp"

namespace scanplan::test_support {

// The 3DTK sample scans, which live in shared/ beside the repository, not inside it.
inline std::filesystem::path threedtk_sample_dir() {
  return std::filesystem::path(SCANPLAN_SOURCE_DIR) / ".." / "shared" / "data" / "3dtk-scans";
}

// A fresh directory for the running test, removed with everything in it when this goes.
class TempDir {
 public:
  TempDir() {
    const auto* t = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("scanplan_" + std::string(t->test_suite_name()) + "_" + t->name() + "_" +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

  // Writes `bytes` as they are to the file `name` in this directory.
  void write(const std::string& name, const std::string& bytes) const {
    std::ofstream(path_ / name, std::ios::binary) << bytes;
  }

 private:
  std::filesystem::path path_;
};

// The same points, bit for bit, and the same colours.
inline void expect_same(const PointCloud& a, const PointCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a.points[i], b.points[i]) << "point " << i;
  EXPECT_EQ(a.colors, b.colors);
}

// Runs `read` and checks that it throws an `Error` whose message holds every fragment.
template <typename Error = ScanFileError, typename F>
void expect_error(F&& read, std::initializer_list<std::string> fragments) {
  try {
    read();
    ADD_FAILURE() << "expected an error, but none was thrown";
  } catch (const Error& e) {
    for (const auto& f : fragments) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos)
          << "'" << f << "' not in: " << e.what();
    }
  }
}

// The bytes of `v` in the byte order `order`, to build binary files by hand.
template <typename T>
std::string bytes_of(T v, std::endian order) {
  std::array<char, sizeof(T)> b;
  std::memcpy(b.data(), &v, sizeof(T));
  if (order != std::endian::native) std::reverse(b.begin(), b.end());
  return std::string(b.data(), b.size());
}

template <typename T>
std::string little_endian(T v) {
  return bytes_of(v, std::endian::little);
}

template <typename T>
std::string big_endian(T v) {
  return bytes_of(v, std::endian::big);
}

}  // namespace scanplan::test_support
