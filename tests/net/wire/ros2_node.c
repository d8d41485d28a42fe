/* ros2_node: the DDS side of a ROS 2 node that runs `ros2 topic list` and `ros2 topic echo`, with
 * its middleware set up the way rmw_cyclonedds_cpp sets itself up, from the same environment
 * variables. No ROS 2 here (Debian 12 has none), so this is the next best thing: a plain Cyclone
 * DDS participant whose domain is created from the very configuration string rmw_cyclonedds
 * passes to dds_create_domain. Shares no code with the platform.
 *
 *   ros2_node --distro humble|jazzy --domain N --expect /ros/name [--expect ...]
 *             [--echo /ros/name] [--timeout S]
 *
 * Environment, read as rmw_cyclonedds reads it:
 *   ROS_LOCALHOST_ONLY=1  humble: rmw_localhost_only enabled; jazzy: the LOCALHOST automatic
 *                         discovery range (rcl maps the deprecated variable to it); otherwise
 *                         jazzy's default range SUBNET.
 *   CYCLONEDDS_URI        appended after rmw's own fragment, as rmw does.
 *
 * The configuration, from ros2/rmw_cyclonedds, rmw_cyclonedds_cpp/src/rmw_node.cpp,
 * check_create_domain():
 *   humble (branch humble, 7cb3b38, lines 1052-1077): localhost-only is the one fragment
 *     <CycloneDDS><Domain><General><Interfaces><NetworkInterface address="127.0.0.1"/>
 *     </Interfaces></General></Domain></CycloneDDS>,   then $CYCLONEDDS_URI.
 *     Everything else is Cyclone's default: AllowMulticast "default" (multicast whenever the
 *     interface's flags say it can), ParticipantIndex "none" (random unicast ports), no peers.
 *   jazzy (branch jazzy, 2ec6f21, lines 1114-1241; rcl 9.2.0 init.c 157-194 maps
 *     ROS_LOCALHOST_ONLY=1 to this range): range LOCALHOST is
 *     <CycloneDDS><Domain><General><AllowMulticast>false</AllowMulticast></General>
 *     <Discovery><ParticipantIndex>auto</ParticipantIndex>
 *     <MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>
 *     <Peers><Peer address="localhost"/></Peers></Discovery></Domain></CycloneDDS>,
 *     (no interface: Cyclone picks one); SUBNET the same without AllowMulticast and Peers.
 *
 * Prints the configuration as the first JSON line ({"config": ...}), then every remote endpoint
 * as it is discovered ({"kind": "publication"|"subscription", "topic": "rt/...", "type": ...}),
 * then, with --echo, the first PoseStamped read from that topic ({"echo": ..., "position": [...]})
 * through best-effort QoS (the default of `ros2 topic echo` against a best-effort publisher).
 * Exit 0 once every --expect topic (mapped to rt/...) was seen and the echo read a sample; none
 * within --timeout (default 10 s): exit 1 with one line on stderr naming what is missing. Bad
 * arguments: exit 2 with one line on stderr.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dds/dds.h"
#include "ros2_wire.h"

#define kMaxExpect 32
#define kNameLen 256

enum Distro { kHumble, kJazzy };

struct Options {
  enum Distro distro;
  long domain;
  char expect[kMaxExpect][kNameLen]; /* DDS names: rt/... */
  bool seen[kMaxExpect];
  int n_expect;
  char echo[kNameLen];
  double timeout_s;
};

static int usage(const char* msg, const char* arg) {
  fprintf(stderr,
          "ros2_node: %s%s%s (usage: --distro humble|jazzy --domain N --expect /ros/name [--expect ...] "
          "[--echo /ros/name] [--timeout S])\n",
          msg, arg ? ": " : "", arg ? arg : "");
  return 2;
}

/* ROS 2 name /x/y is DDS topic rt/x/y (rmw_cyclonedds_cpp's prefix for message topics). */
static int to_dds_name(const char* ros, char out[kNameLen]) {
  if (ros[0] != '/' || ros[1] == '\0') return 0;
  return snprintf(out, kNameLen, "rt%s", ros) < kNameLen;
}

static int parse_args(int argc, char** argv, struct Options* o, int* rc) {
  int have_distro = 0, have_domain = 0;
  memset(o, 0, sizeof *o);
  o->timeout_s = 10.0;
  for (int i = 1; i < argc; ++i) {
    const char* flag = argv[i];
    if (i + 1 >= argc) {
      *rc = usage("missing value", flag);
      return 0;
    }
    const char* value = argv[++i];
    if (strcmp(flag, "--distro") == 0) {
      if (strcmp(value, "humble") == 0) {
        o->distro = kHumble;
      } else if (strcmp(value, "jazzy") == 0) {
        o->distro = kJazzy;
      } else {
        *rc = usage("--distro must be humble or jazzy", value);
        return 0;
      }
      have_distro = 1;
    } else if (strcmp(flag, "--domain") == 0) {
      char* end = NULL;
      errno = 0;
      o->domain = strtol(value, &end, 10);
      if (errno != 0 || end == value || *end != '\0' || o->domain < 0 || o->domain > 230) {
        *rc = usage("--domain must be an integer in 0..230", value);
        return 0;
      }
      have_domain = 1;
    } else if (strcmp(flag, "--expect") == 0) {
      if (o->n_expect == kMaxExpect || !to_dds_name(value, o->expect[o->n_expect])) {
        *rc = usage("--expect must be a ROS 2 name starting with '/' (at most 32 of them)", value);
        return 0;
      }
      ++o->n_expect;
    } else if (strcmp(flag, "--echo") == 0) {
      if (!to_dds_name(value, o->echo)) {
        *rc = usage("--echo must be a ROS 2 name starting with '/'", value);
        return 0;
      }
    } else if (strcmp(flag, "--timeout") == 0) {
      char* end = NULL;
      const double t = strtod(value, &end);
      if (end == value || *end != '\0' || !(t > 0.0) || !(t <= 3600.0)) {
        *rc = usage("--timeout must be a number of seconds in (0, 3600]", value);
        return 0;
      }
      o->timeout_s = t;
    } else {
      *rc = usage("unknown flag", flag);
      return 0;
    }
  }
  if (!have_distro || !have_domain || o->n_expect == 0) {
    *rc = usage("--distro, --domain and at least one --expect are required", NULL);
    return 0;
  }
  return 1;
}

/* The string rmw_cyclonedds passes to dds_create_domain (see the top of this file). Returns a
 * malloc'ed string, NULL when CYCLONEDDS_URI is too long to be sane. */
static char* rmw_config(enum Distro distro) {
  const char* lo = getenv("ROS_LOCALHOST_ONLY");
  const bool localhost_only = lo != NULL && strcmp(lo, "1") == 0;
  const char* uri = getenv("CYCLONEDDS_URI");
  if (uri == NULL) uri = "";
  const char* own = "";
  if (distro == kHumble) {
    if (localhost_only)
      own =
          "<CycloneDDS><Domain><General><Interfaces><NetworkInterface address=\"127.0.0.1\"/>"
          "</Interfaces></General></Domain></CycloneDDS>,";
  } else if (localhost_only) {
    own =
        "<CycloneDDS><Domain><General><AllowMulticast>false</AllowMulticast></General>"
        "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
        "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"
        "<Peers><Peer address=\"localhost\"/></Peers></Discovery></Domain></CycloneDDS>,";
  } else {
    own =
        "<CycloneDDS><Domain><Discovery><ParticipantIndex>auto</ParticipantIndex>"
        "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex></Discovery></Domain></CycloneDDS>,";
  }
  const size_t n_own = strlen(own), n_uri = strlen(uri);
  if (n_uri > 65536) return NULL;
  char* config = malloc(n_own + n_uri + 1);
  if (config == NULL) return NULL;
  memcpy(config, own, n_own);
  memcpy(config + n_own, uri, n_uri + 1);
  return config;
}

static double monotonic_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void put_string(const char* s) {
  putchar('"');
  for (const unsigned char* p = (const unsigned char*)(s ? s : ""); *p; ++p) {
    if (*p == '"' || *p == '\\') {
      printf("\\%c", *p);
    } else if (*p < 0x20) {
      printf("\\u%04x", *p);
    } else {
      putchar(*p);
    }
  }
  putchar('"');
}

static int fail(const char* what, dds_return_t rc) {
  fprintf(stderr, "ros2_node: %s: %s\n", what, dds_strretcode(rc));
  return 1;
}

/* Takes what `reader` (a builtin endpoint reader) discovered: prints remote endpoints, marks the
 * expected topics seen. Endpoints of this participant (the echo's reader) are left out. */
static void take_endpoints(dds_entity_t reader, const char* kind, const dds_guid_t* self, struct Options* o) {
  void* samples[1] = {NULL};
  dds_sample_info_t info[1];
  dds_return_t n;
  while ((n = dds_take(reader, samples, info, 1, 1)) > 0) {
    const dds_builtintopic_endpoint_t* e = samples[0];
    if (info[0].valid_data && info[0].instance_state == DDS_IST_ALIVE &&
        memcmp(&e->participant_key, self, sizeof *self) != 0) {
      fputs("{\"kind\":", stdout);
      put_string(kind);
      fputs(",\"topic\":", stdout);
      put_string(e->topic_name);
      fputs(",\"type\":", stdout);
      put_string(e->type_name);
      fputs("}\n", stdout);
      fflush(stdout);
      for (int i = 0; i < o->n_expect; ++i)
        if (strcmp(e->topic_name, o->expect[i]) == 0) o->seen[i] = true;
    }
    dds_return_loan(reader, samples, n);
    samples[0] = NULL;
  }
}

static bool take_echo(dds_entity_t reader, const char* topic) {
  void* samples[1] = {NULL};
  dds_sample_info_t info[1];
  dds_return_t n;
  bool got = false;
  while (!got && (n = dds_take(reader, samples, info, 1, 1)) > 0) {
    if (info[0].valid_data) {
      const geometry_msgs_msg_dds__PoseStamped_* m = samples[0];
      fputs("{\"echo\":", stdout);
      put_string(topic);
      fputs(",\"frame_id\":", stdout);
      put_string(m->header_.frame_id_);
      printf(",\"position\":[%.17g,%.17g,%.17g]}\n", m->pose_.position_.x_, m->pose_.position_.y_,
             m->pose_.position_.z_);
      fflush(stdout);
      got = true;
    }
    dds_return_loan(reader, samples, n);
    samples[0] = NULL;
  }
  return got;
}

static int run(struct Options* o) {
  char* config = rmw_config(o->distro);
  if (config == NULL) {
    fprintf(stderr, "ros2_node: CYCLONEDDS_URI longer than 64 KiB\n");
    return 2;
  }
  fputs("{\"config\":", stdout);
  put_string(config);
  fputs("}\n", stdout);
  fflush(stdout);

  const dds_entity_t domain = dds_create_domain((dds_domainid_t)o->domain, config);
  free(config);
  if (domain < 0) return fail("cannot create the domain", domain);
  int rc = 1;
  const dds_entity_t pp = dds_create_participant((dds_domainid_t)o->domain, NULL, NULL);
  dds_guid_t self;
  if (pp < 0 || dds_get_guid(pp, &self) < 0) {
    rc = fail("cannot create a participant", pp);
    goto out;
  }
  const dds_entity_t pubs = dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, NULL, NULL);
  const dds_entity_t subs = dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, NULL, NULL);
  if (pubs < 0 || subs < 0) {
    rc = fail("cannot read the builtin topics", pubs < 0 ? pubs : subs);
    goto out;
  }
  dds_entity_t echo = 0;
  if (o->echo[0] != '\0') {
    const dds_entity_t topic =
        dds_create_topic(pp, &geometry_msgs_msg_dds__PoseStamped__desc, o->echo, NULL, NULL);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
    echo = topic < 0 ? topic : dds_create_reader(pp, topic, qos, NULL);
    dds_delete_qos(qos);
    if (echo < 0) {
      rc = fail("cannot create the echo's reader", echo);
      goto out;
    }
  }
  const dds_entity_t ws = dds_create_waitset(pp);
  const dds_entity_t readers[3] = {pubs, subs, echo};
  for (int i = 0; i < 3; ++i) {
    if (readers[i] == 0) continue;
    const dds_entity_t cond = dds_create_readcondition(readers[i], DDS_ANY_STATE);
    if (ws < 0 || cond < 0 || dds_waitset_attach(ws, cond, 0) < 0) {
      rc = fail("cannot create the waitset", ws < 0 ? ws : cond);
      goto out;
    }
  }

  const double end = monotonic_s() + o->timeout_s;
  bool echoed = echo == 0;
  for (;;) {
    take_endpoints(pubs, "publication", &self, o);
    take_endpoints(subs, "subscription", &self, o);
    if (!echoed) echoed = take_echo(echo, o->echo);
    bool all = echoed;
    for (int i = 0; i < o->n_expect; ++i) all = all && o->seen[i];
    if (all) {
      rc = 0;
      break;
    }
    const double left = end - monotonic_s();
    if (left <= 0) {
      fprintf(stderr, "ros2_node: within %g s on DDS domain %ld, not discovered:", o->timeout_s, o->domain);
      for (int i = 0; i < o->n_expect; ++i)
        if (!o->seen[i]) fprintf(stderr, " %s", o->expect[i]);
      if (!echoed) fprintf(stderr, "; no sample read on %s", o->echo);
      fputc('\n', stderr);
      rc = 1;
      break;
    }
    dds_waitset_wait(ws, NULL, 0, (dds_duration_t)(left * 1e9));
  }
out:
  dds_delete(domain);
  return rc;
}

int main(int argc, char** argv) {
  struct Options o;
  int rc = 0;
  if (!parse_args(argc, argv, &o, &rc)) return rc;
  return run(&o);
}
