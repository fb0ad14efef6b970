// SPDX-License-Identifier: Apache-2.0
#include "common/link/dds/dds_entities.h"

#include "common/link/dds/dds_participant.h"

#include <string>

namespace impetus {
namespace {

struct Qos {
  dds_qos_t* qos = dds_create_qos();
  ~Qos() { dds_delete_qos(qos); }
};

void set_delivery(dds_qos_t* qos, Delivery delivery) {
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  if (delivery == Delivery::best_effort) {
    dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  } else {
    // A reliable writer with keep-last history never waits for room; the blocking time only bounds a write while
    // DDS itself is busy.
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(10));
  }
  dds_qset_durability(qos, delivery == Delivery::reliable_durable ? DDS_DURABILITY_TRANSIENT_LOCAL
                                                                    : DDS_DURABILITY_VOLATILE);
}

}  // namespace

// The partition is set on the publisher and subscriber: it is what separates worlds sharing a domain.
dds_entity_t make_publisher(dds_entity_t participant, const std::string& partition) {
  Qos qos;
  dds_qset_partition1(qos.qos, partition.c_str());
  return dds_check(dds_create_publisher(participant, qos.qos, nullptr), "cannot create a DDS publisher");
}

dds_entity_t make_subscriber(dds_entity_t participant, const std::string& partition) {
  Qos qos;
  dds_qset_partition1(qos.qos, partition.c_str());
  return dds_check(dds_create_subscriber(participant, qos.qos, nullptr), "cannot create a DDS subscriber");
}

dds_entity_t make_topic(dds_entity_t participant, const dds_topic_descriptor_t* type, const char* name) {
  return dds_check(dds_create_topic(participant, type, name, nullptr, nullptr),
                   std::string("cannot create DDS topic ") + name);
}

namespace {

// "the topic NAME", and on a secured link why it may be refused.
std::string about_topic(dds_entity_t topic, const char* role) {
  char name[128] = {};
  dds_get_name(topic, name, sizeof name);
  return std::string(" to ") + role + " topic " + name +
         " (on a secured link: do this participant's permissions, --dds-security DIR/permissions.p7s, allow it?)";
}

}  // namespace

dds_entity_t make_writer(dds_entity_t publisher, dds_entity_t topic, Delivery delivery) {
  Qos qos;
  set_delivery(qos.qos, delivery);
  return dds_check(dds_create_writer(publisher, topic, qos.qos, nullptr),
                   "cannot create a DDS writer" + about_topic(topic, "publish"));
}

dds_entity_t make_reader(dds_entity_t subscriber, dds_entity_t topic, Delivery delivery) {
  Qos qos;
  set_delivery(qos.qos, delivery);
  return dds_check(dds_create_reader(subscriber, topic, qos.qos, nullptr),
                   "cannot create a DDS reader" + about_topic(topic, "subscribe"));
}

}  // namespace impetus
