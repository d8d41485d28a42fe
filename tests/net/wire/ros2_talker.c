/* ros2_talker: a plain C publisher of one sensor_msgs/msg/JointState, as `ros2 topic pub --once`
 * with a latched (transient-local) QoS would send it, built only from the ROS 2 IDL in this
 * directory and Cyclone DDS's C API: nothing of the platform's code. The wire-compatibility test
 * sets the platform's microscope with it (/microcobot/slave/microscope/command).
 *
 *   ros2_talker --domain N --topic /ros/name --joint NAME=VALUE [--joint NAME=VALUE] [--timeout S]
 *
 * Waits for a matched reader, writes the message (stamped now), waits until every matched reader
 * acknowledged it, then exits 0. No reader, or no acknowledgement, within S seconds (default 10):
 * exit 1 with one line on stderr. Bad arguments: exit 2 with one line on stderr.
 *
 * Reliable, transient local, keep last 1; the same middleware configuration as ros2_listener
 * (loopback, the platform's discovery).
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dds/dds.h"
#include "ros2_wire.h"

#include "loopback_config.h"

#define kMaxJoints 4

struct Options {
  long domain;
  const char* topic;
  char* names[kMaxJoints];
  double positions[kMaxJoints];
  unsigned joints;
  double timeout_s;
};

static int usage(const char* msg, const char* arg) {
  fprintf(stderr,
          "ros2_talker: %s%s%s (usage: --domain N --topic /ros/name --joint NAME=VALUE [--joint ...] "
          "[--timeout S])\n",
          msg, arg ? ": " : "", arg ? arg : "");
  return 2;
}

static int parse(int argc, char** argv, struct Options* o) {
  o->domain = -1;
  o->topic = NULL;
  o->joints = 0;
  o->timeout_s = 10.0;
  for (int i = 1; i < argc; i += 2) {
    const char* flag = argv[i];
    if (i + 1 >= argc) return usage("a value is missing after", flag);
    char* value = argv[i + 1];
    char* end = NULL;
    if (strcmp(flag, "--domain") == 0) {
      errno = 0;
      o->domain = strtol(value, &end, 10);
      if (errno != 0 || *end != '\0' || o->domain < 0 || o->domain > 232) return usage("bad --domain", value);
    } else if (strcmp(flag, "--topic") == 0) {
      if (value[0] != '/') return usage("--topic must be a ROS 2 name starting with /", value);
      o->topic = value;
    } else if (strcmp(flag, "--joint") == 0) {
      char* eq = strchr(value, '=');
      if (eq == NULL || eq == value || o->joints == kMaxJoints)
        return usage("--joint must be NAME=VALUE", value);
      *eq = '\0';
      const double x = strtod(eq + 1, &end);
      if (end == eq + 1 || *end != '\0') return usage("--joint's value must be a number", eq + 1);
      o->names[o->joints] = value;
      o->positions[o->joints++] = x;
    } else if (strcmp(flag, "--timeout") == 0) {
      o->timeout_s = strtod(value, &end);
      if (end == value || *end != '\0' || !(o->timeout_s > 0.0) || !(o->timeout_s <= 3600.0))
        return usage("--timeout must be a number of seconds in (0, 3600]", value);
    } else {
      return usage("unknown flag", flag);
    }
  }
  if (o->domain < 0 || o->topic == NULL || o->joints == 0)
    return usage("--domain, --topic and at least one --joint are required", NULL);
  return 0;
}

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int fail(const char* what, dds_return_t rc) {
  fprintf(stderr, "ros2_talker: %s: %s\n", what, dds_strretcode(rc));
  return 1;
}

int main(int argc, char** argv) {
  struct Options o;
  const int bad = parse(argc, argv, &o);
  if (bad) return bad;
  char dds_topic[256];
  if (snprintf(dds_topic, sizeof dds_topic, "rt%s", o.topic) >= (int)sizeof dds_topic)
    return usage("topic name too long", o.topic);
  const dds_entity_t domain = dds_create_domain((dds_domainid_t)o.domain, kLoopbackConfig);
  if (domain < 0) return fail("cannot create the domain", domain);
  int rc = 1;
  const dds_entity_t pp = dds_create_participant((dds_domainid_t)o.domain, NULL, NULL);
  if (pp < 0) {
    rc = fail("cannot create a participant", pp);
    goto out;
  }
  const dds_entity_t topic =
      dds_create_topic(pp, &sensor_msgs_msg_dds__JointState__desc, dds_topic, NULL, NULL);
  if (topic < 0) {
    rc = fail("cannot create the topic", topic);
    goto out;
  }
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t writer = dds_create_writer(pp, topic, qos, NULL);
  dds_delete_qos(qos);
  if (writer < 0) {
    rc = fail("cannot create the writer", writer);
    goto out;
  }
  const double deadline = now_s() + o.timeout_s;
  for (;;) {
    dds_publication_matched_status_t st;
    if (dds_get_publication_matched_status(writer, &st) >= 0 && st.current_count > 0) break;
    if (now_s() >= deadline) {
      fprintf(stderr, "ros2_talker: no reader of %s within %g s\n", o.topic, o.timeout_s);
      goto out;
    }
    dds_sleepfor(DDS_MSECS(10));
  }
  struct timespec wall;
  clock_gettime(CLOCK_REALTIME, &wall);
  sensor_msgs_msg_dds__JointState_ m;
  memset(&m, 0, sizeof m);
  m.header_.stamp_.sec_ = (int32_t)wall.tv_sec;
  m.header_.stamp_.nanosec_ = (uint32_t)wall.tv_nsec;
  m.header_.frame_id_ = "";
  m.name_._length = m.name_._maximum = o.joints;
  m.name_._buffer = o.names;
  m.position_._length = m.position_._maximum = o.joints;
  m.position_._buffer = o.positions;
  const dds_return_t w = dds_write(writer, &m);
  if (w < 0) {
    rc = fail("cannot write", w);
    goto out;
  }
  const double left = deadline - now_s();
  const dds_return_t acked = dds_wait_for_acks(writer, (dds_duration_t)(1e9 * (left > 0.1 ? left : 0.1)));
  if (acked < 0) {
    rc = fail("the readers did not acknowledge", acked);
    goto out;
  }
  printf("{\"topic\":\"%s\",\"joints\":%u}\n", o.topic, o.joints);
  rc = 0;
out:
  dds_delete(domain);
  return rc;
}
