/* Sample messages, one per type and payload, built from formulas that
 * tests/proto/test_python_codec.py repeats exactly (all values are dyadic
 * fractions, so C and Python compute them bit for bit). */
#ifndef PROTO_SAMPLES_H
#define PROTO_SAMPLES_H

#include <stddef.h>

#include "proto_msg.h"

int proto_sample_count(void);
const char *proto_sample_name(int k);
/* Index of the sample with this name, -1 if none. */
int proto_sample_find(const char *name);
/* Fills m with sample k. Its arrays live in static storage shared by all
 * samples: valid until the next proto_sample_build(). */
void proto_sample_build(int k, struct proto_msg *m);

/* 1 if a and b carry the same header fields, arrays and text (doubles
 * compared bit for bit, so NaN probes compare equal); else 0 and why. */
int proto_msg_same(const struct proto_msg *a, const struct proto_msg *b, char *why, size_t n);

#endif
