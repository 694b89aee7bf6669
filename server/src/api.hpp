#pragma once

#include <chrono>
#include <string>

#include "annotations.hpp"
#include "auth.hpp"
#include "dds_link.hpp"
#include "http/router.hpp"
#include "mission.hpp"
#include "scan_store.hpp"

namespace scanplan::server {

// The REST API (DESIGN.md "REST"): handlers translate HTTP to calls on the store and the DDS
// link and back; they hold no state of their own beyond the session's start time.
class Api {
 public:
  Api(ScanStore& store, ScanIntake& intake, DdsLink& dds, Mission& mission,
      Annotations& annotations, const Auth& auth, std::string session_dir);
  void install(http::Router& router);

 private:
  // Throws HttpError 401/403 unless the request carries a token with at least `needed`.
  void require(const http::Request& request, Role needed) const;

  http::Response health() const;
  http::Response session(const http::Request& request) const;
  http::Response map_drc(const http::Request& request) const;
  http::Response layer(const std::string& name) const;
  http::Response request_scan(const http::Request& request);
  http::Response post_scan(const http::Request& request);
  http::Response list_scans() const;
  http::Response get_scan(const std::string& id) const;
  http::Response candidates(const http::Request& request) const;
  http::Response get_params() const;
  http::Response put_params(const http::Request& request);
  http::Response post_goal(const http::Request& request);
  http::Response decisions(const http::Request& request) const;
  http::Response decide(const http::Request& request, const std::string& id,
                        const std::string& action);
  http::Response list_annotations() const;
  http::Response post_annotation(const http::Request& request);
  http::Response delete_annotation(const http::Request& request, const std::string& id);

  ScanStore& store_;
  ScanIntake& intake_;
  DdsLink& dds_;
  Mission& mission_;
  Annotations& annotations_;
  const Auth& auth_;
  std::string session_dir_;
  std::chrono::system_clock::time_point started_;
};

}  // namespace scanplan::server
