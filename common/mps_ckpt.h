/* A solver's complete state as one byte image of named blocks, and that image
 * as a checkpoint file (docs/restart.md).
 *
 * One definition of "the complete state" per solver: a solver writes its
 * state into an image (mps_ckpt_put, block after block) and reads it back in
 * the same order (mps_ckpt_get checks each block's name and size). Implicit
 * coupling's rollback keeps the image in memory; a checkpoint writes the same
 * image, with the driver's own blocks (counters, the resolved case), to a file.
 *
 * Image: blocks of [u16 name length][name][u64 bytes][bytes], each part
 * after the name padded to 8 bytes (data read in place), host byte
 * order (a checkpoint is read back by the same build on the same machine
 * kind: bit-identical restarts need that anyway).
 * File DIR/checkpoint/PREFIX_NNNNNN.ckpt (NNNNNN = the checkpoint's number):
 *   "MPSCKPT1", u32 version, u32 0, f64 time, i64 number, u64 image bytes,
 *   the image, u64 FNV-1a hash of the image.
 * Written to PATH.tmp, flushed to disk (fsync), then renamed: a process
 * killed while writing leaves the previous checkpoints as they were. */
#ifndef MPS_CKPT_H
#define MPS_CKPT_H

#include <stddef.h>

#include "mps_err.h"

#define MPS_CKPT_DIR "checkpoint"   /* under the run's output directory */
#define MPS_CKPT_KEEP 2             /* checkpoints kept per process */

/* An image being written (len grows) or read (pos advances). Zero-initialise;
 * it owns buf. */
struct mps_ckpt {
    unsigned char *buf;
    size_t len, cap, pos;
    double time;      /* the file header's time and number (mps_ckpt_read_file) */
    long number;
};

/* Empties the image for writing (keeps the memory). */
void mps_ckpt_clear(struct mps_ckpt *c);
/* Back to the first block, for reading again. */
void mps_ckpt_rewind(struct mps_ckpt *c);
void mps_ckpt_free(struct mps_ckpt *c);

/* Appends block name with bytes of data. */
enum mps_status mps_ckpt_put(struct mps_ckpt *c, const char *name, const void *data,
                             size_t bytes, struct mps_err *err);
/* Reads the next block, which must be called name and hold exactly bytes. */
enum mps_status mps_ckpt_get(struct mps_ckpt *c, const char *name, void *data, size_t bytes,
                             struct mps_err *err);
/* Reads the next block, which must be called name, of any size: *data points
 * into the image (valid until it changes), *bytes is its size. */
enum mps_status mps_ckpt_get_any(struct mps_ckpt *c, const char *name, const void **data,
                                 size_t *bytes, struct mps_err *err);

/* 1 if the image holds a block called name (anywhere; the read position
 * does not move), 0 if not: a section a newer version adds, asked before it
 * is needed. */
int mps_ckpt_has(const struct mps_ckpt *c, const char *name);
/* The same, and where the block is: *data points into the image, *bytes is
 * its size (either may be NULL). */
int mps_ckpt_peek(const struct mps_ckpt *c, const char *name, const void **data,
                  size_t *bytes);

/* DIR/checkpoint/PREFIX_NNNNNN.ckpt into path (size len). */
void mps_ckpt_path(char *path, size_t len, const char *dir, const char *prefix, long number);

/* Writes the image as checkpoint number of time into DIR/checkpoint/
 * (created), atomically, then removes that directory's checkpoints of prefix
 * other than the last MPS_CKPT_KEEP up to number (later ones are from a run
 * this one replaced). path (size len, may be NULL) receives the file name. */
enum mps_status mps_ckpt_write_file(const struct mps_ckpt *c, const char *dir,
                                    const char *prefix, long number, double time, char *path,
                                    size_t len, struct mps_err *err);
/* Reads a checkpoint file into c (replacing its image), checking its hash. */
enum mps_status mps_ckpt_read_file(struct mps_ckpt *c, const char *path, struct mps_err *err);

/* The checkpoint of prefix in DIR/checkpoint/ to restart from: the latest,
 * or with from >= 0 the one nearest to time from. path (size len) receives
 * its name. MPS_EINPUT if there is none. */
enum mps_status mps_ckpt_find(const char *dir, const char *prefix, double from, char *path,
                              size_t len, struct mps_err *err);

#endif
