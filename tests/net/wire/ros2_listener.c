/* ros2_listener: a plain C subscriber to the platform's ROS 2 topics, built only from the ROS 2
 * IDL in this directory (ros2_wire.idl, compiled by idlc) and Cyclone DDS's C API. It knows
 * nothing of the platform's own code: it finds a topic by its ROS 2 name, with ROS 2's DDS type
 * name, and prints what it reads. The wire-compatibility test (wire_compat_test.cc) checks the
 * values against what `microcobot link ping` publishes.
 *
 *   ros2_listener --domain N --topic /microcobot/slave/pose
 *                 --type pose|wrench|vector3|joint|bool|diag|image|tf
 *                 [--count K] [--timeout S] [--ready-file PATH]
 *
 * Waits for K samples (default 1) and prints each as one JSON line on stdout, then exits 0.
 * No K samples within S seconds (default 10): exit 1 with one line on stderr. Bad arguments:
 * exit 2 with one line on stderr. --ready-file: the file is created once the reader exists (a
 * test starts the publisher after it).
 *
 * Same middleware configuration as the platform (loopback, unicast discovery on 127.0.0.1 and
 * multicast participant discovery on lo), same QoS as its publishers: state topics best effort, volatile,
 * keep last 1; the latched topics (bool: /microcobot/estop, /microcobot/master/engaged) reliable, transient
 * local, keep last 1 so that the current state arrives even when published before the start;
 * /diagnostics (diag) reliable, volatile, keep last 1. Images (sensor_msgs/msg/CompressedImage,
 * the camera's frames) are best effort like the state topics; their JPEG is decoded here
 * (libjpeg-turbo's C API) and printed as its width, height and mean grey level. /tf (tf2_msgs/msg/TFMessage)
 * is read as tf2_ros's TransformListener does: reliable, volatile, keep last 100.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <turbojpeg.h>

#include "dds/dds.h"
#include "ros2_wire.h"

#include "loopback_config.h"

enum MsgType { kPose, kWrench, kVector3, kJoint, kBool, kDiag, kImage, kTf };

struct Options {
  long domain;
  const char* topic;
  enum MsgType type;
  long count;
  double timeout_s;
  const char* ready_file;
};

static int usage(const char* msg, const char* arg) {
  fprintf(stderr,
          "ros2_listener: %s%s%s (usage: --domain N --topic /ros/name --type "
          "pose|wrench|vector3|joint|bool|diag|image|tf "
          "[--count K] [--timeout S] [--ready-file PATH])\n",
          msg, arg ? ": " : "", arg ? arg : "");
  return 2;
}

static int parse_long(const char* s, long lo, long hi, long* out) {
  char* end = NULL;
  errno = 0;
  const long v = strtol(s, &end, 10);
  if (errno != 0 || end == s || *end != '\0' || v < lo || v > hi) return 0;
  *out = v;
  return 1;
}

static int parse_args(int argc, char** argv, struct Options* o, int* rc) {
  int have_domain = 0, have_type = 0;
  o->domain = 0;
  o->topic = NULL;
  o->type = kPose;
  o->count = 1;
  o->timeout_s = 10.0;
  o->ready_file = NULL;
  for (int i = 1; i < argc; ++i) {
    const char* flag = argv[i];
    if (i + 1 >= argc) {
      *rc = usage("missing value", flag);
      return 0;
    }
    const char* value = argv[++i];
    if (strcmp(flag, "--domain") == 0) {
      if (!parse_long(value, 0, 230, &o->domain)) {
        *rc = usage("--domain must be an integer in 0..230", value);
        return 0;
      }
      have_domain = 1;
    } else if (strcmp(flag, "--topic") == 0) {
      if (value[0] != '/' || value[1] == '\0') {
        *rc = usage("--topic must be a ROS 2 name starting with '/'", value);
        return 0;
      }
      o->topic = value;
    } else if (strcmp(flag, "--type") == 0) {
      if (strcmp(value, "pose") == 0) {
        o->type = kPose;
      } else if (strcmp(value, "wrench") == 0) {
        o->type = kWrench;
      } else if (strcmp(value, "vector3") == 0) {
        o->type = kVector3;
      } else if (strcmp(value, "joint") == 0) {
        o->type = kJoint;
      } else if (strcmp(value, "bool") == 0) {
        o->type = kBool;
      } else if (strcmp(value, "diag") == 0) {
        o->type = kDiag;
      } else if (strcmp(value, "image") == 0) {
        o->type = kImage;
      } else if (strcmp(value, "tf") == 0) {
        o->type = kTf;
      } else {
        *rc = usage("--type must be pose, wrench, vector3, joint, bool, diag, image or tf", value);
        return 0;
      }
      have_type = 1;
    } else if (strcmp(flag, "--count") == 0) {
      if (!parse_long(value, 1, 1000000, &o->count)) {
        *rc = usage("--count must be an integer in 1..1000000", value);
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
    } else if (strcmp(flag, "--ready-file") == 0) {
      o->ready_file = value;
    } else {
      *rc = usage("unknown flag", flag);
      return 0;
    }
  }
  if (!have_domain || o->topic == NULL || !have_type) {
    *rc = usage("--domain, --topic and --type are required", NULL);
    return 0;
  }
  return 1;
}

static double monotonic_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- JSON output ---------------------------------------------------------------------------- */

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

/* %.17g: the double as sent, bit for bit; JSON has no NaN or infinity, so those are null. */
static void put_double(double v) {
  if (isfinite(v)) {
    printf("%.17g", v);
  } else {
    fputs("null", stdout);
  }
}

static void put_doubles(const double* v, uint32_t n) {
  putchar('[');
  for (uint32_t i = 0; i < n; ++i) {
    if (i) putchar(',');
    put_double(v[i]);
  }
  putchar(']');
}

static void put_header(const char* topic, const char* type_name, const std_msgs_msg_dds__Header_* h) {
  fputs("{\"topic\":", stdout);
  put_string(topic);
  fputs(",\"type\":", stdout);
  put_string(type_name);
  printf(",\"stamp\":{\"sec\":%ld,\"nanosec\":%lu},\"frame_id\":", (long)h->stamp_.sec_,
         (unsigned long)h->stamp_.nanosec_);
  put_string(h->frame_id_);
}

/* The JPEG of a CompressedImage decoded: its size and mean level (grey: one byte a pixel). */
static void put_jpeg(const sensor_msgs_msg_dds__CompressedImage_* m) {
  int width = 0, height = 0, subsamp = 0, colorspace = 0;
  tjhandle tj = tjInitDecompress();
  unsigned char* pixels = NULL;
  int ok = tj != NULL && m->data_._length > 0 &&
           tjDecompressHeader3(tj, m->data_._buffer, m->data_._length, &width, &height, &subsamp,
                               &colorspace) == 0 &&
           width > 0 && height > 0;
  if (ok) {
    pixels = malloc((size_t)width * (size_t)height);
    ok = pixels != NULL &&
         tjDecompress2(tj, m->data_._buffer, m->data_._length, pixels, width, 0, height, TJPF_GRAY, 0) == 0;
  }
  if (ok) {
    double sum = 0.0;
    for (size_t i = 0; i < (size_t)width * (size_t)height; ++i) sum += pixels[i];
    printf(",\"jpeg\":{\"width\":%d,\"height\":%d,\"mean\":", width, height);
    put_double(sum / ((double)width * (double)height));
    putchar('}');
  } else {
    fputs(",\"jpeg\":null", stdout);
  }
  free(pixels);
  if (tj) tjDestroy(tj);
}

static void print_sample(const struct Options* o, const char* type_name, const void* sample) {
  switch (o->type) {
    case kPose: {
      const geometry_msgs_msg_dds__PoseStamped_* m = sample;
      const double pos[3] = {m->pose_.position_.x_, m->pose_.position_.y_, m->pose_.position_.z_};
      const double rot[4] = {m->pose_.orientation_.x_, m->pose_.orientation_.y_, m->pose_.orientation_.z_,
                             m->pose_.orientation_.w_};
      put_header(o->topic, type_name, &m->header_);
      fputs(",\"position\":", stdout);
      put_doubles(pos, 3);
      fputs(",\"orientation\":", stdout);
      put_doubles(rot, 4);
      break;
    }
    case kWrench: {
      const geometry_msgs_msg_dds__WrenchStamped_* m = sample;
      const double f[3] = {m->wrench_.force_.x_, m->wrench_.force_.y_, m->wrench_.force_.z_};
      const double t[3] = {m->wrench_.torque_.x_, m->wrench_.torque_.y_, m->wrench_.torque_.z_};
      put_header(o->topic, type_name, &m->header_);
      fputs(",\"force\":", stdout);
      put_doubles(f, 3);
      fputs(",\"torque\":", stdout);
      put_doubles(t, 3);
      break;
    }
    case kVector3: {
      const geometry_msgs_msg_dds__Vector3Stamped_* m = sample;
      const double v[3] = {m->vector_.x_, m->vector_.y_, m->vector_.z_};
      put_header(o->topic, type_name, &m->header_);
      fputs(",\"vector\":", stdout);
      put_doubles(v, 3);
      break;
    }
    case kJoint: {
      const sensor_msgs_msg_dds__JointState_* m = sample;
      put_header(o->topic, type_name, &m->header_);
      fputs(",\"name\":[", stdout);
      for (uint32_t i = 0; i < m->name_._length; ++i) {
        if (i) putchar(',');
        put_string(m->name_._buffer[i]);
      }
      fputs("],\"position\":", stdout);
      put_doubles(m->position_._buffer, m->position_._length);
      fputs(",\"velocity\":", stdout);
      put_doubles(m->velocity_._buffer, m->velocity_._length);
      fputs(",\"effort\":", stdout);
      put_doubles(m->effort_._buffer, m->effort_._length);
      break;
    }
    case kDiag: {
      const diagnostic_msgs_msg_dds__DiagnosticArray_* m = sample;
      put_header(o->topic, type_name, &m->header_);
      fputs(",\"status\":[", stdout);
      for (uint32_t i = 0; i < m->status_._length; ++i) {
        const diagnostic_msgs_msg_dds__DiagnosticStatus_* st = &m->status_._buffer[i];
        printf("%s{\"level\":%u,\"name\":", i ? "," : "", (unsigned)st->level_);
        put_string(st->name_);
        fputs(",\"message\":", stdout);
        put_string(st->message_);
        fputs(",\"hardware_id\":", stdout);
        put_string(st->hardware_id_);
        printf(",\"values\":%u}", (unsigned)st->values_._length);
      }
      putchar(']');
      break;
    }
    case kImage: {
      const sensor_msgs_msg_dds__CompressedImage_* m = sample;
      put_header(o->topic, type_name, &m->header_);
      fputs(",\"format\":", stdout);
      put_string(m->format_);
      printf(",\"bytes\":%lu", (unsigned long)m->data_._length);
      put_jpeg(m);
      break;
    }
    case kTf: {
      const tf2_msgs_msg_dds__TFMessage_* m = sample;
      fputs("{\"topic\":", stdout);
      put_string(o->topic);
      fputs(",\"type\":", stdout);
      put_string(type_name);
      fputs(",\"transforms\":[", stdout);
      for (uint32_t i = 0; i < m->transforms_._length; ++i) {
        const geometry_msgs_msg_dds__TransformStamped_* t = &m->transforms_._buffer[i];
        const double xyz[3] = {t->transform_.translation_.x_, t->transform_.translation_.y_,
                               t->transform_.translation_.z_};
        const double q[4] = {t->transform_.rotation_.x_, t->transform_.rotation_.y_,
                             t->transform_.rotation_.z_, t->transform_.rotation_.w_};
        printf("%s{\"stamp\":{\"sec\":%d,\"nanosec\":%u},\"parent\":", i ? "," : "",
               (int)t->header_.stamp_.sec_, (unsigned)t->header_.stamp_.nanosec_);
        put_string(t->header_.frame_id_);
        fputs(",\"child\":", stdout);
        put_string(t->child_frame_id_);
        fputs(",\"translation\":", stdout);
        put_doubles(xyz, 3);
        fputs(",\"rotation\":", stdout);
        put_doubles(q, 4);
        putchar('}');
      }
      putchar(']');
      break;
    }
    case kBool: {
      const std_msgs_msg_dds__Bool_* m = sample;
      fputs("{\"topic\":", stdout);
      put_string(o->topic);
      fputs(",\"type\":", stdout);
      put_string(type_name);
      printf(",\"data\":%s", m->data_ ? "true" : "false");
      break;
    }
  }
  fputs("}\n", stdout);
  fflush(stdout);
}

/* ---- DDS ------------------------------------------------------------------------------------ */

static const dds_topic_descriptor_t* descriptor(enum MsgType t) {
  switch (t) {
    case kPose:
      return &geometry_msgs_msg_dds__PoseStamped__desc;
    case kWrench:
      return &geometry_msgs_msg_dds__WrenchStamped__desc;
    case kVector3:
      return &geometry_msgs_msg_dds__Vector3Stamped__desc;
    case kJoint:
      return &sensor_msgs_msg_dds__JointState__desc;
    case kBool:
      return &std_msgs_msg_dds__Bool__desc;
    case kDiag:
      return &diagnostic_msgs_msg_dds__DiagnosticArray__desc;
    case kImage:
      return &sensor_msgs_msg_dds__CompressedImage__desc;
    case kTf:
      return &tf2_msgs_msg_dds__TFMessage__desc;
  }
  return NULL;
}

static int fail(const char* what, dds_return_t rc) {
  fprintf(stderr, "ros2_listener: %s: %s\n", what, dds_strretcode(rc));
  return 1;
}

static int run_listener(const struct Options* o) {
  const dds_topic_descriptor_t* desc = descriptor(o->type);
  /* ROS 2 name /x/y is DDS topic rt/x/y (rmw_cyclonedds_cpp's topic prefix for messages). */
  char dds_topic[256];
  if (snprintf(dds_topic, sizeof dds_topic, "rt%s", o->topic) >= (int)sizeof dds_topic) {
    fprintf(stderr, "ros2_listener: topic name too long: %s\n", o->topic);
    return 2;
  }

  const dds_entity_t domain = dds_create_domain((dds_domainid_t)o->domain, kLoopbackConfig);
  if (domain < 0) return fail("cannot create the domain", domain);
  int rc = 1;
  const dds_entity_t pp = dds_create_participant((dds_domainid_t)o->domain, NULL, NULL);
  if (pp < 0) {
    rc = fail("cannot create a participant", pp);
    goto out;
  }
  const dds_entity_t topic = dds_create_topic(pp, desc, dds_topic, NULL, NULL);
  if (topic < 0) {
    rc = fail("cannot create the topic", topic);
    goto out;
  }
  dds_qos_t* qos = dds_create_qos();
  if (o->type == kBool) {
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  } else if (o->type == kDiag || o->type == kTf) {
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  } else {
    dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  }
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, o->type == kTf ? 100 : 1);
  const dds_entity_t reader = dds_create_reader(pp, topic, qos, NULL);
  dds_delete_qos(qos);
  if (reader < 0) {
    rc = fail("cannot create the reader", reader);
    goto out;
  }
  const dds_entity_t cond = dds_create_readcondition(reader, DDS_ANY_STATE);
  const dds_entity_t ws = dds_create_waitset(pp);
  if (cond < 0 || ws < 0 || dds_waitset_attach(ws, cond, 0) < 0) {
    rc = fail("cannot create the waitset", cond < 0 ? cond : ws);
    goto out;
  }
  if (o->ready_file) {
    FILE* f = fopen(o->ready_file, "w");
    if (f) fclose(f);
  }

  const double end = monotonic_s() + o->timeout_s;
  long got = 0;
  while (got < o->count) {
    const double left = end - monotonic_s();
    if (left <= 0) break;
    dds_waitset_wait(ws, NULL, 0, (dds_duration_t)(left * 1e9));
    void* samples[1] = {NULL};
    dds_sample_info_t info[1];
    dds_return_t n;
    while (got < o->count && (n = dds_take(reader, samples, info, 1, 1)) > 0) {
      if (info[0].valid_data) {
        print_sample(o, desc->m_typename, samples[0]);
        ++got;
      }
      dds_return_loan(reader, samples, n);
      samples[0] = NULL;
    }
  }
  if (got < o->count) {
    fprintf(stderr, "ros2_listener: %ld of %ld samples on %s (%s, DDS domain %ld) within %g s\n", got,
            o->count, dds_topic, desc->m_typename, o->domain, o->timeout_s);
    rc = 1;
  } else {
    rc = 0;
  }
out:
  dds_delete(domain);
  return rc;
}

int main(int argc, char** argv) {
  struct Options o;
  int rc = 0;
  if (!parse_args(argc, argv, &o, &rc)) return rc;
  return run_listener(&o);
}
