/* libFuzzer target: the protocol decoder (proto_msg_decode) on any frames.
 * Input layout: byte 0 = number of frames (mod PROTO_MAX_FRAMES + 2, so
 * too many frames are tried too), then per frame a little-endian u16 length
 * and that many bytes (cut short by the input's end). Everything decode
 * accepts is encoded again and must decode to the same message (the codec is
 * a bijection on valid messages), and the text helpers run on its text. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "proto_msg.h"

#define MAX_IN (PROTO_MAX_FRAMES + 2)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    int nf = data[0] % (MAX_IN + 1);
    size_t pos = 1;
    struct proto_frame fr[MAX_IN];
    /* each frame in a buffer of its own, so ASan sees a read past its end */
    void *own[MAX_IN] = {0};
    for (int k = 0; k < nf; k++) {
        size_t len = 0;
        if (pos + 2 <= size) {
            len = (size_t)data[pos] | ((size_t)data[pos + 1] << 8);
            pos += 2;
        } else {
            pos = size;
        }
        if (len > size - pos)
            len = size - pos;
        own[k] = malloc(len ? len : 1);
        if (len)
            memcpy(own[k], data + pos, len);
        fr[k] = (struct proto_frame){len ? own[k] : NULL, len};
        pos += len;
    }
    struct proto_msg m;
    struct mps_err err;
    if (proto_msg_decode(&m, nf ? fr : NULL, nf, &err) == MPS_OK) {
        struct proto_frames enc;
        if (proto_msg_encode(&m, &enc, &err) != MPS_OK)
            abort(); /* decoded but not encodable: the two disagree */
        struct proto_msg again;
        if (proto_msg_decode(&again, enc.f, enc.n, &err) != MPS_OK)
            abort();
        if (again.type != m.type || again.count != m.count || again.nprobes != m.nprobes ||
            (m.text && strcmp(m.text, again.text) != 0))
            abort();
        char buf[64];
        if (m.text) {
            proto_text_get(m.text, ' ', "role", buf, sizeof buf);
            proto_text_get(m.text, '\n', "case", buf, sizeof buf);
            proto_error_status(m.text, NULL);
        }
        proto_msg_clear(&again);
        proto_frames_clear(&enc);
        proto_msg_clear(&m);
    }
    for (int k = 0; k < nf; k++)
        free(own[k]);
    return 0;
}
