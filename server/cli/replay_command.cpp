#include "replay_command.hpp"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "http_client.hpp"

namespace scanplan::cli {
namespace {

using nlohmann::json;

struct ReplayArgs {
  std::string script, server, token;
};

// "${NAME}" becomes the environment variable NAME, so scripts need not contain secrets.
std::string expand(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    if (s.compare(i, 2, "${") == 0) {
      const auto end = s.find('}', i);
      if (end != std::string::npos) {
        const char* v = std::getenv(s.substr(i + 2, end - i - 2).c_str());
        out += v ? v : "";
        i = end + 1;
        continue;
      }
    }
    out += s[i++];
  }
  return out;
}

// Whether `actual` holds everything `expected` says, with the reasons where it does not.
// Objects match by subset, arrays element by element for the expected length, and
// {"approx": v, "tol": t} matches any number within t of v.
void match(const json& expected, const json& actual, const std::string& where,
           std::vector<std::string>& errors) {
  if (expected.is_object() && expected.contains("approx") && expected.size() <= 2) {
    const double v = expected.at("approx").get<double>();
    const double tol = expected.value("tol", 0.0);
    if (!actual.is_number() || std::abs(actual.get<double>() - v) > tol) {
      errors.push_back(where + ": expected " + std::to_string(v) + " ± " + std::to_string(tol) +
                       ", got " + actual.dump());
    }
    return;
  }
  if (expected.is_object()) {
    if (!actual.is_object()) {
      errors.push_back(where + ": expected an object, got " + actual.dump());
      return;
    }
    for (const auto& [k, v] : expected.items()) {
      if (!actual.contains(k)) {
        errors.push_back(where + "." + k + ": missing");
      } else {
        match(v, actual.at(k), where + "." + k, errors);
      }
    }
    return;
  }
  if (expected.is_array()) {
    if (!actual.is_array() || actual.size() < expected.size()) {
      errors.push_back(where + ": expected an array of at least " +
                       std::to_string(expected.size()) + " elements, got " +
                       actual.dump().substr(0, 200));
      return;
    }
    for (std::size_t i = 0; i < expected.size(); ++i) {
      match(expected[i], actual[i], where + "[" + std::to_string(i) + "]", errors);
    }
    return;
  }
  const bool same = expected.is_number() && actual.is_number()
                        ? expected.get<double>() == actual.get<double>()
                        : expected == actual;
  if (!same)
    errors.push_back(where + ": expected " + expected.dump() + ", got " +
                     actual.dump().substr(0, 200));
}

std::vector<std::string> check(const json& expect, const HttpResult& r) {
  std::vector<std::string> errors;
  if (expect.contains("status") && expect.at("status").get<int>() != r.status) {
    errors.push_back("status: expected " + expect.at("status").dump() + ", got " +
                     std::to_string(r.status) + " " + r.body.substr(0, 300));
  }
  if (expect.contains("headers")) {
    for (const auto& [k, v] : expect.at("headers").items()) {
      std::string name = k;
      for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      const auto it = r.headers.find(name);
      if (it == r.headers.end() || it->second != v.get<std::string>()) {
        errors.push_back("header " + k + ": expected " + v.dump() + ", got " +
                         (it == r.headers.end() ? "none" : "\"" + it->second + "\""));
      }
    }
  }
  if (expect.contains("json")) {
    json body;
    try {
      body = json::parse(r.body);
    } catch (const json::exception&) {
      errors.push_back("body: not JSON: " + r.body.substr(0, 200));
      return errors;
    }
    match(expect.at("json"), body, "json", errors);
  }
  return errors;
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int run_replay(const ReplayArgs& a) {
  const std::filesystem::path script_path(a.script);
  json script;
  try {
    script = json::parse(read_file(script_path));
  } catch (const json::parse_error& e) {
    throw std::runtime_error(a.script + ": not valid JSON: " + e.what());
  }
  if (!script.contains("steps") || !script.at("steps").is_array()) {
    throw std::runtime_error(a.script + ": a replay script needs a \"steps\" array");
  }
  const HttpClient client(a.server);
  const std::string name = script.value("name", script_path.stem().string());
  json failures = json::array();
  int passed = 0, failed = 0;
  for (std::size_t i = 0; i < script.at("steps").size(); ++i) {
    const json& step = script.at("steps")[i];
    const json& req = step.at("request");
    const json expect = step.value("expect", json::object());
    std::map<std::string, std::string> headers;
    if (!a.token.empty()) headers["Authorization"] = "Bearer " + a.token;
    const json step_headers = req.value("headers", json::object());
    for (const auto& [k, v] : step_headers.items()) {
      headers[k] = expand(v.get<std::string>());
    }
    std::string body;
    if (req.contains("body_file")) {
      body = read_file(script_path.parent_path() / req.at("body_file").get<std::string>());
    } else if (req.contains("body")) {
      const json& b = req.at("body");
      body = b.is_string() ? b.get<std::string>() : b.dump();
      if (!b.is_string() && !headers.count("Content-Type"))
        headers["Content-Type"] = "application/json";
    }
    const std::string method = req.value("method", "GET");
    const std::string path = expand(req.at("path").get<std::string>());
    // An extension of the format: "until" repeats the request until it meets its expectations
    // (for what the server does after answering, such as planning), within timeout_s.
    const double timeout_s =
        step.contains("until") ? step.at("until").value("timeout_s", 30.0) : 0.0;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    std::vector<std::string> errors;
    for (;;) {
      try {
        errors = check(expect, client.request(method, path, headers, body));
      } catch (const HttpClientError& e) {
        errors = {e.what()};
      }
      if (errors.empty() || std::chrono::steady_clock::now() >= deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
    const std::string label = "step " + std::to_string(i + 1) + " " + method + " " + path;
    if (errors.empty()) {
      ++passed;
      std::cerr << "ok     " << label << "\n";
    } else {
      ++failed;
      std::cerr << "FAILED " << label << "\n";
      for (const auto& e : errors) std::cerr << "         " << e << "\n";
      failures.push_back({{"step", i + 1}, {"request", method + " " + path}, {"errors", errors}});
    }
  }
  std::cout << json{{"name", name},
                    {"steps", passed + failed},
                    {"passed", passed},
                    {"failed", failed},
                    {"failures", failures}}
                   .dump()
            << std::endl;
  std::cerr << passed << " passed, " << failed << " failed\n";
  return failed == 0 ? 0 : 1;
}

}  // namespace

void add_replay_command(CLI::App& app) {
  auto args = std::make_shared<ReplayArgs>();
  CLI::App* cmd = app.add_subcommand("replay", "run a REST replay script against a server");
  cmd->add_option("script", args->script, "the replay script (*.replay.json)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--server", args->server, "server URL, e.g. http://127.0.0.1:8080")->required();
  cmd->add_option("--token", args->token,
                  "bearer token sent with every request (default: $SCANPLAN_TOKEN)")
      ->envname("SCANPLAN_TOKEN");
  cmd->callback([args] {
    const int rc = run_replay(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace scanplan::cli
