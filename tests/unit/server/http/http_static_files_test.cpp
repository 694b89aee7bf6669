#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "http/static_files.hpp"

namespace fs = std::filesystem;

namespace scanplan::http {
namespace {

void write_file(const fs::path& p, const std::string& content) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << content;
}

// A scratch tree:  <tmp>/secret.txt  and the root <tmp>/web with a few assets and symlinks.
class HttpStaticFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    dir_ = fs::temp_directory_path() /
           ("scanplan_http_static_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(dir_);
    root_ = dir_ / "web";
    write_file(dir_ / "secret.txt", "TOP SECRET");
    write_file(dir_ / "web2" / "x.txt", "sibling");
    write_file(root_ / "index.html", "<html>index</html>");
    write_file(root_ / "app.js", "console.log(1)");
    write_file(root_ / "style.CSS", "body{}");
    write_file(root_ / "draco_decoder.wasm", std::string("\0asm", 4));
    write_file(root_ / "docs" / "index.html", "<html>docs</html>");
    write_file(root_ / "assets" / "map.drc", "DRACO");
    fs::create_directory_symlink(dir_, root_ / "up");
    fs::create_symlink(dir_ / "secret.txt", root_ / "secret-link.txt");
    fs::create_symlink(root_ / "app.js", root_ / "alias.js");
    fs::create_directory_symlink("../web2", root_ / "sibling");
  }
  void TearDown() override { fs::remove_all(dir_); }

  Response get(const std::string& path, const std::string& method = "GET") const {
    Request r;
    r.method = method;
    r.path = path;
    r.target = path;
    return StaticFiles(root_).serve(r);
  }

  fs::path dir_;
  fs::path root_;
};

TEST_F(HttpStaticFilesTest, ServesIndexForRootWithNoCache) {
  const Response r = get("/");
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.body, "<html>index</html>");
  EXPECT_EQ(r.header("Content-Type"), "text/html; charset=utf-8");
  EXPECT_EQ(r.header("Cache-Control"), "no-cache");
  EXPECT_EQ(get("/docs/").body, "<html>docs</html>");
  EXPECT_EQ(get("/docs").body, "<html>docs</html>");
}

TEST_F(HttpStaticFilesTest, ContentTypes) {
  EXPECT_EQ(get("/app.js").header("Content-Type"), "text/javascript; charset=utf-8");
  EXPECT_EQ(get("/style.CSS").header("Content-Type"), "text/css; charset=utf-8");
  const Response wasm = get("/draco_decoder.wasm");
  EXPECT_EQ(wasm.header("Content-Type"), "application/wasm");
  EXPECT_EQ(wasm.body, std::string("\0asm", 4));
  EXPECT_EQ(get("/assets/map.drc").header("Content-Type"), "application/octet-stream");
  EXPECT_FALSE(get("/app.js").header("Cache-Control").has_value());
}

TEST_F(HttpStaticFilesTest, MissingFileIsJson404) {
  const Response r = get("/nope.js");
  EXPECT_EQ(r.status, 404);
  EXPECT_EQ(nlohmann::json::parse(r.body)["error"]["code"], "not_found");
  EXPECT_EQ(get("/assets/").status, 404);  // a directory without index.html
}

TEST_F(HttpStaticFilesTest, RefusesDotDotAndNul) {
  EXPECT_EQ(get("/../secret.txt").status, 400);
  EXPECT_EQ(get("/docs/../../secret.txt").status, 400);
  EXPECT_EQ(get("/..").status, 400);
  EXPECT_EQ(get(std::string("/index.html\0.png", 16)).status, 400);
}

TEST_F(HttpStaticFilesTest, SymlinksCannotLeaveTheRoot) {
  EXPECT_EQ(get("/secret-link.txt").status, 404);
  EXPECT_EQ(get("/up/secret.txt").status, 404);
  EXPECT_EQ(get("/sibling/x.txt").status, 404) << "a prefix of the root's name is not inside it";
  EXPECT_EQ(get("/alias.js").body, "console.log(1)") << "links inside the root are fine";
}

TEST_F(HttpStaticFilesTest, DoubleSlashDoesNotBecomeAbsolute) {
  EXPECT_EQ(get("//etc/passwd").status, 404);
  EXPECT_EQ(get("//app.js").status, 200);
  EXPECT_EQ(get("/./app.js").status, 200);
}

TEST_F(HttpStaticFilesTest, OnlyGetAndHead) {
  EXPECT_EQ(get("/app.js", "HEAD").status, 200);
  const Response r = get("/app.js", "POST");
  EXPECT_EQ(r.status, 405);
  EXPECT_EQ(r.header("Allow"), "GET, HEAD");
}

TEST_F(HttpStaticFilesTest, RootMustBeADirectory) {
  EXPECT_THROW(StaticFiles(dir_ / "missing"), std::invalid_argument);
  EXPECT_THROW(StaticFiles(dir_ / "secret.txt"), std::invalid_argument);
  // A root given through a symlink or with "..": files are still found.
  Request r;
  r.method = "GET";
  r.path = "/app.js";
  EXPECT_EQ(StaticFiles(root_ / "docs" / "..").serve(r).status, 200);
}

}  // namespace
}  // namespace scanplan::http
