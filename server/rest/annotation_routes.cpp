#include "rest/api.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "app/domain_json.hpp"
#include "http/http_error.hpp"
#include "rest/request_parsing.hpp"

namespace scanplan::server {

using http::HttpError;
using http::Request;
using http::Response;
using nlohmann::json;

namespace {

const char* const kAnnotationShape =
    "an annotation is {\"kind\": \"victim|hazard|blocked|note\", \"x\": m, \"y\": m, "
    "\"z\": m, \"text\": \"...\"} with optional \"by\": \"your name\"";

}  // namespace

Response Api::list_annotations() const {
  json list = json::array();
  for (const Annotation& a : app_.annotations.list()) list.push_back(annotation_json(a));
  return Response::json(200, {{"annotations", list}});
}

Response Api::post_annotation(const Request& request) {
  const json body = rest::object_body(request, kAnnotationShape);
  for (const auto& [key, value] : body.items()) {
    if (key != "kind" && key != "x" && key != "y" && key != "z" && key != "text" && key != "by") {
      throw HttpError(400, "bad_request", "unknown field '" + key + "': " + kAnnotationShape);
    }
  }
  if (!body.contains("kind") || !body["kind"].is_string() ||
      std::find(kAnnotationKinds.begin(), kAnnotationKinds.end(),
                body["kind"].get<std::string>()) == kAnnotationKinds.end()) {
    throw HttpError(400, "bad_request",
                    "'kind' must be \"victim\", \"hazard\", \"blocked\" or \"note\", got " +
                        (body.contains("kind") ? body["kind"].dump() : std::string("nothing")));
  }
  const std::string kind = body["kind"].get<std::string>();
  const double x = rest::coordinate(body, "x"), y = rest::coordinate(body, "y"),
               z = rest::coordinate(body, "z");
  const std::string text = rest::text_in(body, "text", kMaxAnnotationTextBytes, TextKind::kProse);
  if (kind == "note" && text.empty()) {
    throw HttpError(400, "bad_request", "'text' is required for a note");
  }
  const std::string author = rest::author_of(body);
  try {
    return Response::json(201, annotation_json(app_.annotations.add(kind, x, y, z, text, author)));
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed",
                    std::string("the annotation could not be stored: ") + e.what());
  }
}

Response Api::delete_annotation(const Request& request, const std::string& id) {
  const auto n = static_cast<std::int64_t>(rest::path_id(id, "an annotation id"));
  std::string by = "operator";
  if (!request.body.empty()) {
    const json body =
        rest::object_body(request, "the body, when given, is {\"by\": \"your name\"}");
    for (const auto& [key, value] : body.items()) {
      if (key != "by") throw HttpError(400, "bad_request", "unknown field '" + key + "'");
    }
    by = rest::author_of(body);
  }
  try {
    if (!app_.annotations.remove(n, by)) {
      throw HttpError(404, "not_found", "no annotation " + id + " in this session");
    }
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed",
                    std::string("the deletion could not be stored: ") + e.what());
  }
  return Response::json(200, {{"id", n}, {"deleted", true}, {"by", by}});
}

}  // namespace scanplan::server
