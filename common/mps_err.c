#include "mps_err.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

enum mps_status mps_err_set(struct mps_err *e, enum mps_status code, const char *fmt, ...)
{
    if (!e)
        return code;
    e->code = code;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e->msg, sizeof e->msg, fmt, ap);
    va_end(ap);
    return code;
}

enum mps_status mps_err_prefix(struct mps_err *e, const char *fmt, ...)
{
    if (!e)
        return MPS_OK;
    char head[256], old[sizeof e->msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(head, sizeof head, fmt, ap);
    va_end(ap);
    memcpy(old, e->msg, sizeof old);
    size_t hl = strlen(head);
    memcpy(e->msg, head, hl);
    snprintf(e->msg + hl, sizeof e->msg - hl, "%.*s", (int)(sizeof e->msg - hl - 1), old);
    return e->code;
}

void mps_err_clear(struct mps_err *e)
{
    if (e) {
        e->code = MPS_OK;
        e->msg[0] = '\0';
    }
}

const char *mps_status_name(enum mps_status code)
{
    switch (code) {
    case MPS_OK: return "ok";
    case MPS_EINPUT: return "input";
    case MPS_EIO: return "io";
    case MPS_ENOMEM: return "memory";
    case MPS_ELIB: return "library";
    case MPS_ESOLVE: return "solver";
    case MPS_EDIVERGED: return "diverged";
    case MPS_EPROTO: return "protocol";
    case MPS_ETIMEOUT: return "timeout";
    case MPS_EPEER: return "peer";
    case MPS_EINTR: return "interrupted";
    }
    return "unknown";
}

int mps_status_exit_code(enum mps_status code)
{
    switch (code) {
    case MPS_OK: return 0;
    case MPS_EINPUT: return 2;
    case MPS_EINTR: return 130;
    default: return 1;
    }
}
