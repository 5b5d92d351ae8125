/* cursor.c - opaque, per-viewer page cursors (see cursor.h), with Debian's nettle. */
#include "cursor.h"

#include <nettle/aes.h>
#include <nettle/hmac.h>
#include <nettle/memops.h>
#include <stdio.h>
#include <string.h>
#include <sys/random.h>

#include "grainpack/error.h"

/* Bytes of the tag in a token: 2^-64 is the chance that a made-up token passes. */
#define TAG_BYTES 8

int gp_cursor_keys_init(gp_cursor_keys *keys)
{
    unsigned char *p = (unsigned char *)keys;
    size_t got = 0;
    while (got < sizeof *keys) {
        ssize_t n = getrandom(p + got, sizeof *keys - got, 0);
        if (n <= 0)
            return GP_EIO;
        got += (size_t)n;
    }
    return 0;
}

/* The tag of seq for viewer: the viewer's kind ('u' and the name, or 'a' for all) and
 * the sequence number, so that a token of one viewer is nothing to another. */
static void tag_of(const gp_cursor_keys *keys, const char *viewer, const unsigned char seq[8],
                   unsigned char tag[SHA256_DIGEST_SIZE])
{
    struct hmac_sha256_ctx ctx;
    hmac_sha256_set_key(&ctx, sizeof keys->mac, keys->mac);
    hmac_sha256_update(&ctx, 1, (const uint8_t *)(viewer ? "u" : "a"));
    if (viewer)
        hmac_sha256_update(&ctx, strlen(viewer) + 1, (const uint8_t *)viewer); /* with its NUL */
    hmac_sha256_update(&ctx, 8, seq);
    hmac_sha256_digest(&ctx, SHA256_DIGEST_SIZE, tag);
}

void gp_cursor_encode(const gp_cursor_keys *keys, const char *viewer, int64_t seq,
                      char out[GP_CURSOR_SIZE])
{
    unsigned char block[AES_BLOCK_SIZE], tag[SHA256_DIGEST_SIZE], sealed[AES_BLOCK_SIZE];
    for (int i = 0; i < 8; i++)
        block[i] = (unsigned char)((uint64_t)seq >> (8 * i));
    tag_of(keys, viewer, block, tag);
    memcpy(block + 8, tag, TAG_BYTES);
    struct aes128_ctx aes;
    aes128_set_encrypt_key(&aes, keys->cipher);
    aes128_encrypt(&aes, AES_BLOCK_SIZE, sealed, block);
    for (int i = 0; i < AES_BLOCK_SIZE; i++)
        snprintf(out + 2 * i, 3, "%02x", sealed[i]);
}

static int hex_value(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
}

int gp_cursor_decode(const gp_cursor_keys *keys, const char *viewer, const char *text,
                     int64_t *seq)
{
    unsigned char sealed[AES_BLOCK_SIZE], block[AES_BLOCK_SIZE], tag[SHA256_DIGEST_SIZE];
    if (strlen(text) != GP_CURSOR_CHARS)
        return -1;
    for (int i = 0; i < AES_BLOCK_SIZE; i++) {
        int hi = hex_value(text[2 * i]), lo = hex_value(text[2 * i + 1]);
        if (hi < 0 || lo < 0)
            return -1;
        sealed[i] = (unsigned char)(hi * 16 + lo);
    }
    struct aes128_ctx aes;
    aes128_set_decrypt_key(&aes, keys->cipher);
    aes128_decrypt(&aes, AES_BLOCK_SIZE, block, sealed);
    tag_of(keys, viewer, block, tag);
    if (!memeql_sec(tag, block + 8, TAG_BYTES))
        return -1;
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)block[i] << (8 * i);
    *seq = (int64_t)v;
    return 0;
}
