// SPDX-License-Identifier: Apache-2.0
#pragma once
// The DDS entities the world link and the world view are made of, created alike: a publisher and a subscriber in the
// link's partition, and writers and readers with one of three deliveries. Each throws std::runtime_error naming what
// DDS refused.

#include <dds/dds.h>

#include <string>

namespace impetus {

// Frames and snapshots best effort (the next one replaces a lost one), reports reliable, the world's info and scene
// reliable and transient local (a late joiner reads them at once); keep last 1 everywhere: only the newest matters.
enum class Delivery { best_effort, reliable, reliable_durable };

dds_entity_t make_publisher(dds_entity_t participant, const std::string& partition);
dds_entity_t make_subscriber(dds_entity_t participant, const std::string& partition);
dds_entity_t make_topic(dds_entity_t participant, const dds_topic_descriptor_t* type, const char* name);
dds_entity_t make_writer(dds_entity_t publisher, dds_entity_t topic, Delivery delivery);
dds_entity_t make_reader(dds_entity_t subscriber, dds_entity_t topic, Delivery delivery);

}  // namespace impetus
