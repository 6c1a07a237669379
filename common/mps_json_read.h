/* Reading one number out of a JSON object: the solvers' summaries (their BYE
 * text, proto/PROTOCOL.md) hold the compute time and the lost particles the
 * coupler reports. Only the top-level members count: a key inside a nested
 * object or array, or quoted inside a string value, is not the member. */
#ifndef MPS_JSON_READ_H
#define MPS_JSON_READ_H

/* Finds the member key of the top-level object in json. Returns 1 and sets
 * *v when its value is a number; 0 when the object has no such member or its
 * value is not a number (null, a string, an object); -1 when the text is not
 * a JSON object up to the member (or to its end). */
int mps_json_top_number(const char *json, const char *key, double *v);

#endif
