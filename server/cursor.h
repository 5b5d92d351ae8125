/* cursor.h - the opaque cursors of GET /jobs: a page's `next` link carries the position
 * of its last job as a token that shows nothing of it (the store's sequence numbers count
 * every user's jobs: a user who could read them would count the others' submissions
 * between two pages) and that only the viewer it was made for can use.
 *
 * A token is one AES-128 block, in hex: the job's sequence number (8 bytes) and the
 * first 8 bytes of an HMAC-SHA256 of the viewer and that number, under two keys drawn at
 * start-up. A cursor is valid until the daemon stops; the nodes of a PostgreSQL store
 * share their keys (kept in the database, gp_store_secret), so any node takes a cursor
 * any other made, for as long as the database lives. */
#ifndef GRAINPACKD_CURSOR_H
#define GRAINPACKD_CURSOR_H

#include <stdint.h>

/* Hex characters of a token, and its size with the NUL. */
#define GP_CURSOR_CHARS 32
#define GP_CURSOR_SIZE (GP_CURSOR_CHARS + 1)

typedef struct gp_cursor_keys {
    unsigned char cipher[16]; /* AES-128 */
    unsigned char mac[32];    /* HMAC-SHA256 */
} gp_cursor_keys;

/* Draws fresh keys from the kernel's random source. Returns 0 or GP_EIO. */
int gp_cursor_keys_init(gp_cursor_keys *keys);

/* The token of position `seq` for `viewer`: a user's name, or NULL for a view of every
 * job (an admin key, or a daemon without keys). */
void gp_cursor_encode(const gp_cursor_keys *keys, const char *viewer, int64_t seq,
                      char out[GP_CURSOR_SIZE]);

/* The position in a token made for `viewer` (as gp_cursor_encode). Returns 0 with *seq,
 * or -1 when the text is not a token this daemon made for this viewer (malformed, made
 * up, another user's, or from before a restart). */
int gp_cursor_decode(const gp_cursor_keys *keys, const char *viewer, const char *text,
                     int64_t *seq);

#endif
