/* A tiny streaming JSON writer for run summaries (summary.json). It keeps
 * track of commas; nesting depth is bounded. */
#ifndef MPS_JSON_H
#define MPS_JSON_H

#include <stdio.h>

struct mps_json {
    FILE *f;
    int depth;
    int first[32];   /* per level: no member written yet */
    char array[32];  /* per level: 1 in an array, 0 in an object (how to close it) */
};

void mps_json_begin(struct mps_json *j, FILE *f);     /* opens the root object */
void mps_json_end(struct mps_json *j);                /* closes the root, newline */
void mps_json_object(struct mps_json *j, const char *key); /* key NULL inside arrays */
void mps_json_array(struct mps_json *j, const char *key);
void mps_json_close(struct mps_json *j);              /* closes object or array */
void mps_json_num(struct mps_json *j, const char *key, double v);  /* NaN/inf -> null */
void mps_json_int(struct mps_json *j, const char *key, long long v);
void mps_json_str(struct mps_json *j, const char *key, const char *v); /* escaped */
void mps_json_bool(struct mps_json *j, const char *key, int v);

#endif
