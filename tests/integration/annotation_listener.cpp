// A plain Cyclone DDS subscriber to scanplan_Annotation, as any other workstation or robot would
// subscribe: transient-local, so it is given every live annotation when it joins. Prints one JSON
// line per annotation, and {"topic", "disposed": id} when one is deleted; used by
// tests/integration/annotations.test.mjs and session_recovery.test.mjs.
// Usage: annotation_listener --domain N [--seconds S]
#include "dds_listener.hpp"
#include "scanplan.h"

int main(int argc, char** argv) {
  using namespace scanplan::test;
  using nlohmann::json;
  try {
    const ListenerArgs args = parse_listener_args(argc, argv);
    const dds_entity_t participant =
        check(dds_create_participant(args.domain, nullptr, nullptr), "creating the participant");
    const dds_entity_t topic = check(dds_create_topic(participant, &scanplan_Annotation_desc,
                                                      "scanplan_Annotation", nullptr, nullptr),
                                     "creating topic scanplan_Annotation");
    // Keep-last 1 per instance, like the writer: one sample per annotation id.
    dds_qos_t* qos = latched_reader_qos();
    const dds_entity_t reader = dds_create_reader(participant, topic, qos, nullptr);
    dds_delete_qos(qos);
    check(reader, "creating a reader for scanplan_Annotation");
    const Subscription sub{
        reader, [](const void* s, const dds_sample_info_t& info) {
          const auto& a = *static_cast<const scanplan_Annotation*>(s);
          if (!info.valid_data) {
            // Only the key is meaningful in an invalid sample.
            if (info.instance_state == DDS_IST_NOT_ALIVE_DISPOSED) {
              emit({{"topic", "scanplan_Annotation"}, {"disposed", a.id}});
            }
            return;
          }
          emit({{"topic", "scanplan_Annotation"},
                {"id", a.id},
                {"kind", a.kind ? a.kind : ""},
                {"x", a.position.x},
                {"y", a.position.y},
                {"z", a.position.z},
                {"text", a.text ? a.text : ""},
                {"author", a.author ? a.author : ""},
                {"stamp_ns",
                 static_cast<std::int64_t>(a.stamp.sec) * 1000000000 + a.stamp.nanosec}});
        }};
    run_listener(participant, {sub}, args.seconds);
    check(dds_delete(participant), "deleting the participant");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "annotation_listener: %s\n", e.what());
    return 1;
  }
  return 0;
}
