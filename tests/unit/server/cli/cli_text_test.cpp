// What the terminal operator prints, from fixed server answers and events: the candidate table,
// the status summary, one line per event, and how the printer treats progress and JSON.
#include <gtest/gtest.h>

#include <cstdlib>
#include <ctime>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "candidate_table.hpp"
#include "event_printer.hpp"
#include "event_text.hpp"
#include "status_report.hpp"
#include "text_format.hpp"

namespace scanplan::cli {
namespace {

using nlohmann::json;

// Event times are shown in local time; the tests pin the zone.
class UtcZone : public ::testing::Environment {
 public:
  void SetUp() override {
    setenv("TZ", "UTC", 1);
    tzset();
  }
};
const auto* const kUtc = ::testing::AddGlobalTestEnvironment(new UtcZone);

json candidates_answer() {
  return json::parse(R"({
    "plan": {"id": 3, "based_on_scan": 2, "robot": "robot1", "policy": "paper", "alpha": 0.5,
             "plan_ms": 1234.4},
    "candidates": [
      {"id": 12, "rank": 1, "state": "proposed", "note": "", "x": 12.34, "y": -4.56, "z": 0.1,
       "f": 1234.5, "gain_unscanned_m2": 1000, "gain_low_res_m2": 234.5, "travel_m": 15.25,
       "score": 1200, "path": [[0, 0], [12.34, -4.56]],
       "registrability": {"overlap_share": 0.456, "pose_fixing": 0.01, "factor": 1}},
      {"id": 13, "rank": 2, "state": "refused", "note": "rubble in the way", "x": -3, "y": 7.5,
       "z": 0, "f": 99, "gain_unscanned_m2": 50, "gain_low_res_m2": 49, "travel_m": 8,
       "score": 90, "path": [],
       "registrability": {"overlap_share": 0.12, "pose_fixing": 0.001, "factor": 0.16}}
    ]})");
}

TEST(CandidateTable, ListsRankIdStatePositionFGainsAndTravel) {
  const std::vector<std::string> expected = {
      "plan 3 after scan 2 (robot robot1, policy paper, alpha 0.50, planned in 1234 ms)",
      "rank     id  state           x m      y m         F  gain U m2  gain M m2  travel m  match",
      "   1     12  proposed       12.3     -4.6    1234.5     1000.0      234.5      15.2    46%",
      "   2     13  refused        -3.0      7.5      99.0       50.0       49.0       8.0    12%? "
      "(rubble in the way)",
  };
  EXPECT_EQ(render_candidate_table(candidates_answer()), expected);
}

TEST(CandidateTable, SeveralRobotsGetALineEachAndARobotColumn) {
  json answer = candidates_answer();
  answer["plans"] = json::array({answer["plan"],
                                 {{"id", 4},
                                  {"based_on_scan", 2},
                                  {"robot", "robot2"},
                                  {"policy", "paper"},
                                  {"alpha", 0.5},
                                  {"plan_ms", 99.6}}});
  answer["candidates"][0]["robot"] = "robot1";
  answer["candidates"][1]["robot"] = "robot2";
  const std::vector<std::string> expected = {
      "plan 3 after scan 2 (robot robot1, policy paper, alpha 0.50, planned in 1234 ms)",
      "plan 4 after scan 2 (robot robot2, policy paper, alpha 0.50, planned in 100 ms)",
      "robot      rank     id  state           x m      y m         F  gain U m2  gain M m2  "
      "travel m  match",
      "robot1        1     12  proposed       12.3     -4.6    1234.5     1000.0      234.5      "
      "15.2    46%",
      "robot2        2     13  refused        -3.0      7.5      99.0       50.0       49.0       "
      "8.0    12%? (rubble in the way)",
  };
  EXPECT_EQ(render_candidate_table(answer), expected);
  // Without a forecast (matching off, the operator's own point): a dash.
  answer["candidates"][0].erase("registrability");
  answer["candidates"][1]["registrability"] = nullptr;
  const std::string row = render_candidate_table(answer)[3];
  EXPECT_EQ(row.substr(row.size() - 2), " -") << row;
  // One robot's plan in "plans" reads as before.
  answer["plans"] = json::array({answer["plan"]});
  EXPECT_EQ(render_candidate_table(answer)[1].substr(0, 4), "rank");
}

TEST(CandidateTable, SaysWhenThereIsNoPlanOrNoCandidate) {
  EXPECT_EQ(render_candidate_table(json::parse(R"({"plan":null,"candidates":[]})")),
            std::vector<std::string>{
                "no plan yet: the planner proposes scan points after the first scan"});
  json empty = candidates_answer();
  empty["candidates"] = json::array();
  EXPECT_EQ(render_candidate_table(empty).back(),
            "no candidates: the planner found no reachable point that sees anything new");
}

TEST(CandidateTable, AMissingFieldIsAnErrorNotAZero) {
  json broken = candidates_answer();
  broken["candidates"][0].erase("f");
  EXPECT_THROW(render_candidate_table(broken), json::exception);
}

TEST(CandidateTable, OneLineSummaryForWatch) {
  EXPECT_EQ(describe_candidate(candidates_answer()["candidates"][0]),
            "1. candidate 12 at (12.3, -4.6): F 1234.5, gains U 1000.0 + M 234.5 m2, travel "
            "15.2 m, proposed");
}

json session_with_scans() {
  return json::parse(R"({
    "session_dir": "/data/s1", "started": "2024-05-01T07:00:00Z", "scans": 2, "points": 300000,
    "bridges": 1,
    "robots": {"robot1": {"state": "moving", "command_id": 4, "message": "",
                          "pose": {"x": 1.25, "y": -2, "z": 0.2, "yaw_deg": 90},
                          "scan": {"command_id": 3, "state": "scanning", "fraction": 0.4,
                                   "message": ""}}},
    "bounds": {"min": [0, 0, 0], "max": [1, 1, 1]},
    "last_scan": {"id": 2, "robot": "robot1", "points": 150000,
                  "pose": {"x": 10, "y": 5, "z": 0, "yaw_deg": 45}},
    "areas": {"completed_m2": 3456.4, "low_resolution_m2": 1234, "unscanned_m2": 35310,
              "movable_m2": 2100}})");
}

json two_scans() {
  return json::parse(R"({"pending": 1, "scans": [
    {"id": 1, "robot": "robot1", "points": 150000, "received_at": "x",
     "estimated": {"x": 0, "y": 0, "z": 0, "yaw_deg": 0},
     "placed": {"x": 0, "y": 0, "z": 0, "yaw_deg": 0}},
    {"id": 2, "robot": "robot1", "points": 150000, "received_at": "x",
     "estimated": {"x": 10.3, "y": 4.6, "z": 0, "yaw_deg": 359},
     "placed": {"x": 10, "y": 5, "z": 0, "yaw_deg": 1}}]})");
}

TEST(StatusReport, SummarisesTheSession) {
  const std::vector<std::string> expected = {
      "server      http://127.0.0.1:8080 (session /data/s1, started 2024-05-01T07:00:00Z)",
      "connection  1 robot bridge connected over DDS",
      "scans       2 scans, 300000 points in the map (1 more being processed)",
      "areas       completed 3456 m2, low-res 1234 m2, unscanned 35310 m2, movable 2100 m2",
      "robots      robot1 moving (command 4), at (1.2, -2.0), z 0.2 m, heading 90 deg",
      "scanning    robot1 scan command 3 scanning [########------------]  40%",
      "last scan   #2 from robot1, 150000 points, placed at (10.0, 5.0), z 0.0 m, heading 45 deg",
      "last match  scan 2 moved 0.50 m by matching: dx -0.30 dy +0.40 dz +0.00 m, dyaw +2.0 deg",
  };
  EXPECT_EQ(render_status("http://127.0.0.1:8080", session_with_scans(), two_scans()), expected);
}

TEST(StatusReport, AnEmptySessionSaysWhatToDo) {
  const json session = json::parse(R"({
    "session_dir": "s", "started": "t", "scans": 0, "points": 0, "bridges": 0, "robots": {},
    "areas": {"completed_m2": 0, "low_resolution_m2": 0, "unscanned_m2": 0, "movable_m2": 0}})");
  const auto lines = render_status("http://h", session, json::parse(R"({"scans":[],"pending":0})"));
  EXPECT_EQ(lines[1], "connection  no robot bridge connected: scans and moves cannot be sent");
  EXPECT_EQ(lines[2], "scans       0 scans, 0 points in the map");
  EXPECT_EQ(lines[4], "robots      none has reported yet");
  EXPECT_EQ(lines[5], "scanning    no scan command so far");
  EXPECT_EQ(lines[6], "last scan   none yet: request one with POST /api/v1/scan");
}

TEST(StatusReport, FirstScanDefinesTheFrame) {
  json scans = two_scans();
  scans["scans"].erase(1);
  EXPECT_EQ(render_status("http://h", session_with_scans(), scans).back(),
            "last match  scan 1 is the first: it defines the map frame");
}

TEST(EventText, DescribesEachEventType) {
  const auto d = [](const char* text) { return describe_event(json::parse(text)); };
  EXPECT_EQ(d(R"({"type":"scan_progress","robot":"robot1","command_id":3,"state":"scanning",
                 "fraction":0.45,"message":""})"),
            "robot1 scan command 3 [#########-----------]  45% scanning");
  EXPECT_EQ(d(R"({"type":"scan_progress","robot":"r","command_id":3,"state":"failed",
                 "fraction":0.45,"message":"shut down"})"),
            "r scan command 3 FAILED at 45%: shut down");
  EXPECT_EQ(d(R"({"type":"match_done","scan":2,"method":"ndt-icp","converged":true,
                 "applied":true,"score":123.44,"rmse":0.0451,"time_ms":350,"message":"",
                 "correction":{"x":0.31,"y":-0.12,"z":0.01,"yaw_deg":1.2}})"),
            "scan 2: ndt-icp converged, score 123.4, rmse 0.045 m, correction dx +0.31 dy -0.12 "
            "dz +0.01 m dyaw +1.2 deg (applied), 350 ms");
  EXPECT_EQ(d(R"({"type":"match_done","scan":3,"method":"ndt-icp","converged":false,
                 "applied":false,"score":8996.2,"rmse":0.157,"time_ms":29,
                 "message":"the match moved the scan 17.4 m",
                 "correction":{"x":0,"y":0,"z":0,"yaw_deg":0}})"),
            "scan 3: ndt-icp did not converge, score 8996.2, rmse 0.157 m (NOT applied: the "
            "robot's estimate is kept), 29 ms: the match moved the scan 17.4 m");
  EXPECT_EQ(d(R"({"type":"map_updated","scan":2,"points":5,"completed_m2":1.4,
                 "low_resolution_m2":2,"unscanned_m2":3,"movable_m2":4})"),
            "scan 2 is in the map: completed 1 m2, low-res 2 m2, unscanned 3 m2, movable 4 m2");
  EXPECT_EQ(d(R"({"type":"plan_done","plan":3,"based_on_scan":2,"candidates":5,"plan_ms":12})"),
            "plan 3 after scan 2: 5 candidates in 12 ms");
  EXPECT_EQ(d(R"({"type":"scan_received","scan":3,"robot":"robot1","points":78000,
                  "dropped":{"non_finite":0,"mount":1973,"saturated":1481}})"),
            "scan 3 from robot1 stored: 78000 points (dropped 0 not finite, 1973 on the mount, "
            "1481 saturated)");
  EXPECT_EQ(d(R"({"type":"scan_received","scan":2,"robot":"robot1","points":150000})"),
            "scan 2 from robot1 stored: 150000 points");
  EXPECT_EQ(d(R"({"type":"scan_received","scan":4,"robot":"r","points":9,
                  "dropped":{"non_finite":1,"out_of_range":2,"mount":0,"saturated":0}})"),
            "scan 4 from r stored: 9 points (dropped 1 not finite, 2 out of range, 0 on the mount, "
            "0 saturated)");
  EXPECT_EQ(d(R"({"type":"scan_rejected","robot":"r","reason":"the pose's x is 1e+07 m"})"),
            "scan from r REFUSED: the pose's x is 1e+07 m");
  EXPECT_EQ(d(R"({"type":"scan_excluded","scan":2,"by":"operator Ann","reason":"ghost walls"})"),
            "scan 2 taken out of the map by operator Ann: ghost walls");
  EXPECT_EQ(d(R"({"type":"scan_restored","scan":2,"by":"operator","reason":""})"),
            "scan 2 put back into the map by operator");
  EXPECT_EQ(d(R"({"type":"map_rebuilt","scans":3,"completed_m2":10.2,"low_resolution_m2":1,
                 "unscanned_m2":2,"movable_m2":5})"),
            "map rebuilt from 3 scans: completed 10 m2, movable 5 m2");
  EXPECT_EQ(d(R"({"type":"mission","kind":"approve","candidate":12,"robot":"robot1",
                 "command_id":4,"x":12.34,"y":-4.5,"yaw_deg":45,"by":"operator Alice"})"),
            "approved candidate 12 by operator Alice: robot1 drives to (12.3, -4.5) heading 45 "
            "deg (command 4)");
  EXPECT_EQ(d(R"({"type":"mission","kind":"reject","candidate":13,"by":"operator",
                 "reason":"rubble"})"),
            "rejected candidate 13 by operator (rubble)");
  EXPECT_EQ(d(R"({"type":"mission","kind":"refused","candidate":13,"robot":"robot1",
                 "message":"no path"})"),
            "robot1 refused to drive to candidate 13: no path");
  EXPECT_EQ(d(R"({"type":"annotation","id":3,"kind":"victim","x":1,"y":2,"z":0.5,
                 "text":"voice heard","author":"operator Bob","created_at":"t"})"),
            "victim #3 at (1.0, 2.0), z 0.5 by operator Bob: voice heard");
  EXPECT_EQ(d(R"({"type":"annotation_deleted","id":3,"by":"operator"})"), "#3 deleted by operator");
  EXPECT_EQ(d(R"({"type":"binary_dropped","count":2,"first_id":3,"last_id":4})"),
            "2 map chunks (scans 3..4) dropped: this link is too slow for them");
  EXPECT_EQ(d(R"({"type":"map_corrected","scans":[3,4,5,6,7,8,9,12],"joined":[14],"left":[],
                 "max_moved_m":0.118,"max_turned_deg":0.12,"revision":7})"),
            "map corrected: scans 3\u20139, 12 moved up to 12 cm / 0.1 deg; scan 14 tied into the "
            "map (pose revision 7)");
  EXPECT_EQ(d(R"({"type":"map_corrected","scans":[],"joined":[],"left":[5,6],
                 "max_moved_m":0,"max_turned_deg":0,"revision":0})"),
            "map corrected: scans 5\u20136 set outside the map until a match agrees again");
  EXPECT_EQ(d(R"({"type":"map_updated","scan":4,"points":10,"in_map":false,"completed_m2":1,
                 "low_resolution_m2":2,"unscanned_m2":3,"movable_m2":4})"),
            "scan 4 waits outside the map until a match ties it in: completed 1 m2, low-res 2 m2, "
            "unscanned 3 m2, movable 4 m2");
  EXPECT_EQ(d(R"({"type":"map_updated","scan":4,"points":10,"in_map":false,
                 "outside":"no match ties it to the map","completed_m2":1,
                 "low_resolution_m2":2,"unscanned_m2":3,"movable_m2":4})"),
            "scan 4 waits outside the map (no match ties it to the map): completed 1 m2, low-res "
            "2 m2, unscanned 3 m2, movable 4 m2");
  EXPECT_EQ(d(R"({"type":"map_updated","scan":4,"points":10,"in_map":true,"outside":null,
                 "completed_m2":1,"low_resolution_m2":2,"unscanned_m2":3,"movable_m2":4})"),
            "scan 4 is in the map: completed 1 m2, low-res 2 m2, unscanned 3 m2, movable 4 m2");
  EXPECT_EQ(d(R"({"type":"something_new","at":"t","value":1})"), R"({"value":1})")
      << "an unknown event is shown, not hidden";
}

std::string map_chunk_frame(std::uint8_t op, std::uint32_t id, std::uint64_t ns,
                            std::size_t payload) {
  std::string f(1, static_cast<char>(op));
  for (int k = 0; k < 4; ++k) f.push_back(static_cast<char>((id >> (8 * k)) & 0xFF));
  for (int k = 0; k < 8; ++k) f.push_back(static_cast<char>((ns >> (8 * k)) & 0xFF));
  return f + std::string(payload, 'd');
}

TEST(EventText, MapChunksAreSummarisedFromTheirLittleEndianHeader) {
  const auto c = parse_map_chunk(map_chunk_frame(1, 0x01020304, 1714547000123456789ull, 1000));
  ASSERT_TRUE(c);
  EXPECT_EQ(c->op, 1);
  EXPECT_EQ(c->id, 0x01020304u);
  EXPECT_EQ(c->sent_ns, 1714547000123456789ull);
  EXPECT_EQ(c->payload_bytes, 1000u);
  EXPECT_EQ(describe_map_chunk(*c), "scan 16909060: 1000 bytes of Draco points (not shown)");
  EXPECT_EQ(
      map_chunk_json(*c).dump(),
      R"({"bytes":1000,"op":1,"scan":16909060,"sent_ns":1714547000123456789,"type":"map_chunk"})");
  EXPECT_FALSE(parse_map_chunk(std::string(12, '\0')));
}

TEST(TextFormat, NumbersBarsAndClocks) {
  EXPECT_EQ(fixed(-0.04, 1), "0.0") << "no minus sign on a zero";
  EXPECT_EQ(signed_fixed(0.31, 2), "+0.31");
  EXPECT_EQ(signed_fixed(-0.31, 2), "-0.31");
  EXPECT_EQ(progress_bar(0, 10), "[----------]   0%");
  EXPECT_EQ(progress_bar(1.5, 10), "[##########] 100%");
  EXPECT_EQ(progress_bar(std::nan(""), 4), "[----]   0%");
  EXPECT_EQ(local_clock_of("2024-05-01T07:41:02Z"), "07:41:02");
  EXPECT_FALSE(local_clock_of("yesterday"));
  EXPECT_EQ(local_clock_of_ns(1714549262000000000ull), "07:41:02");
}

json candidates_for_plan(int plan, int count) {
  json a = candidates_answer();
  a["plan"]["id"] = plan;
  json c = a["candidates"][0];
  a["candidates"] = json::array();
  for (int k = 1; k <= count; ++k) {
    c["rank"] = k;
    c["id"] = 100 + k;
    a["candidates"].push_back(c);
  }
  return a;
}

std::string progress_event(double fraction, const char* state = "scanning") {
  return json{{"type", "scan_progress"},
              {"at", "2024-05-01T07:41:02Z"},
              {"robot", "robot1"},
              {"command_id", 3},
              {"state", state},
              {"fraction", fraction},
              {"message", ""}}
      .dump();
}

TEST(EventPrinter, OneLinePerEventWithTimeTypeAndTheTopCandidatesAfterAPlan) {
  std::ostringstream out, notes;
  EventPrinter p(out, notes, {false, false, 2}, [] { return candidates_for_plan(3, 5); });
  p.text_frame(R"({"type":"plan_done","at":"2024-05-01T07:41:02Z","plan":3,"based_on_scan":2,
                   "candidates":5,"plan_ms":12})");
  EXPECT_EQ(out.str(),
            "07:41:02  plan_done       plan 3 after scan 2: 5 candidates in 12 ms\n"
            "          1. candidate 101 at (12.3, -4.6): F 1234.5, gains U 1000.0 + M 234.5 m2, "
            "travel 15.2 m, proposed\n"
            "          2. candidate 102 at (12.3, -4.6): F 1234.5, gains U 1000.0 + M 234.5 m2, "
            "travel 15.2 m, proposed\n"
            "          (3 more: scanplan candidates)\n");
  EXPECT_EQ(notes.str(), "");
}

TEST(EventPrinter, ANewerPlanOrAFailedFetchIsSaid) {
  std::ostringstream out, notes;
  EventPrinter newer(out, notes, {false, false, 1}, [] { return candidates_for_plan(4, 1); });
  newer.text_frame(R"({"type":"plan_done","plan":3,"based_on_scan":2,"candidates":1,"plan_ms":1})");
  EXPECT_NE(out.str().find("(plan 4 has replaced it since)"), std::string::npos) << out.str();
  std::ostringstream out2;
  EventPrinter failing(out2, notes, {false, false, 1},
                       []() -> json { throw std::runtime_error("server gone"); });
  failing.text_frame(R"({"type":"plan_done","plan":3,"based_on_scan":2,"candidates":1})");
  EXPECT_NE(out2.str().find("(cannot list the candidates: server gone)"), std::string::npos);
}

TEST(EventPrinter, ProgressInALogEveryTenPercent) {
  std::ostringstream out, notes;
  EventPrinter p(out, notes, {false, false, 3}, nullptr);
  for (int k = 0; k <= 100; ++k) p.text_frame(progress_event(k / 100.0));
  p.text_frame(progress_event(1.0, "done"));
  std::istringstream lines(out.str());
  int count = 0;
  for (std::string line; std::getline(lines, line);) ++count;
  EXPECT_EQ(count, 11 + 1) << out.str();  // 0 %, 10 %, ..., 100 %, then done
}

TEST(EventPrinter, ProgressOnATerminalIsRedrawnInPlace) {
  std::ostringstream out, notes;
  EventPrinter p(out, notes, {false, true, 3}, nullptr);
  p.text_frame(progress_event(0.1));
  p.text_frame(progress_event(0.2));
  p.text_frame(R"({"type":"scan_received","at":"2024-05-01T07:41:03Z","scan":1,"robot":"r",
                   "points":5})");
  EXPECT_EQ(out.str(),
            "\r07:41:02  scan_progress   robot1 scan command 3 [##------------------]  10% "
            "scanning\x1b[K"
            "\r07:41:02  scan_progress   robot1 scan command 3 [####----------------]  20% "
            "scanning\x1b[K\n"
            "07:41:03  scan_received   scan 1 from r stored: 5 points\n");
}

TEST(EventPrinter, JsonModePassesEventsThroughAndSummarisesChunks) {
  std::ostringstream out, notes;
  EventPrinter p(out, notes, {true, false, 3}, [] {
    ADD_FAILURE() << "no fetching in json mode";
    return json();
  });
  const std::string event = R"({"type":"plan_done","plan":3})";
  p.text_frame(event);
  p.binary_frame(map_chunk_frame(1, 7, 0, 10));
  p.connection("lost", "the server closed the connection");
  std::istringstream lines(out.str());
  std::string l1, l2, l3;
  std::getline(lines, l1);
  std::getline(lines, l2);
  std::getline(lines, l3);
  EXPECT_EQ(l1, event);
  EXPECT_EQ(json::parse(l2)["scan"], 7);
  EXPECT_EQ(json::parse(l2)["bytes"], 10);
  const json c = json::parse(l3);
  EXPECT_EQ(c["type"], "connection");
  EXPECT_EQ(c["state"], "lost");
  EXPECT_NE(notes.str().find("connection      the server closed the connection"), std::string::npos)
      << "the person at the terminal sees it too";
}

}  // namespace
}  // namespace scanplan::cli
