#include "export_command.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "operator_client.hpp"
#include "operator_error.hpp"

namespace scanplan::cli {
namespace {

struct ExportArgs {
  OperatorOptions o;
  std::string name;
  std::string out;
};

void run_export(const ExportArgs& a) {
  const OperatorClient client(a.o);
  const std::optional<std::string> bytes =
      client.get_bytes("/api/v1/export/" + a.name, "export " + a.name);
  if (!bytes) throw OperatorError(ExitCode::kFailure, "the server sent no " + a.name);
  const std::filesystem::path out = a.out.empty() ? "scanplan-" + a.name : a.out;
  // Written whole or not at all: a full disk leaves no half file for another team to read.
  std::filesystem::path part = out;
  part += ".part";
  {
    std::ofstream file(part, std::ios::binary | std::ios::trunc);
    file.write(bytes->data(), static_cast<std::streamsize>(bytes->size()));
    file.close();
    if (!file) {
      std::error_code ignored;
      std::filesystem::remove(part, ignored);
      throw OperatorError(ExitCode::kFailure, "could not write " + out.string() +
                                                  " (a full disk, or no permission there?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(part, out, ec);
  if (ec) {
    std::filesystem::remove(part, ec);
    throw OperatorError(ExitCode::kFailure,
                        "could not write " + out.string() + ": " + ec.message());
  }
  std::cerr << "wrote " << out.string() << " (" << bytes->size() << " bytes)" << std::endl;
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto a = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "terminal operator: save the registered map (map.ply, map.las), the scans' poses "
      "(poses.csv) or the annotations (annotations.geojson), map frame, to a file");
  cmd->add_option("name", a->name, "what to export")
      ->required()
      ->check(CLI::IsMember({"map.ply", "map.las", "poses.csv", "annotations.geojson"}));
  cmd->add_option("--out", a->out, "the file to write (default: scanplan-NAME here)");
  add_operator_options(cmd, a->o, "(no JSON: the file is the result)");
  cmd->callback([a] { run_operator_command("export", [&] { run_export(*a); }); });
}

}  // namespace scanplan::cli
