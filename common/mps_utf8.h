/* Checking and showing UTF-8 text. */
#ifndef MPS_UTF8_H
#define MPS_UTF8_H

#include <stddef.h>

/* The length of the well-formed UTF-8 sequence at p (1-4 bytes; no overlong
 * forms, surrogates or code points past U+10FFFF), 0 if there is none. */
size_t mps_utf8_seq(const unsigned char *p);

/* 1 if s is UTF-8 text throughout, else 0. */
int mps_utf8_valid(const char *s);

/* s into buf (size n, truncated) with each byte that is not UTF-8 written
 * as \xNN, so a message that reports it is text and shows which bytes.
 * Returns buf. */
const char *mps_utf8_escaped(const char *s, char *buf, size_t n);

#endif
