/* libFuzzer target for what `join` reads besides the videos
 * (capture/cap_seg.c): a segment's manifest (SEG.seg) and its hash list
 * (SEG.hashes, the render's --hashes).  `make fuzz` builds it; seeds in
 * tests/fuzz/seg/.  The first byte picks the parser:
 *   even      the rest is a manifest: what is accepted is within the
 *             manifest's rules (a key join accepts, ticks in order, frames =
 *             END - FIRST, at least a byte a frame) and formats back to a
 *             text that parses to the same manifest;
 *   odd       the rest is a hash list of ticks FIRST..END-1, FIRST from
 *             the next byte (bit 1 of the first byte: from the next eight,
 *             any 64-bit tick), END = FIRST + the number of newlines (bit 2:
 *             + the next byte instead, so the count is wrong too): what is
 *             accepted is exactly "N <16 hex digits>\n" for each tick, and
 *             its FNV-1a is the text's.
 * A refusal must carry the parser's id and a message naming the file. */
#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../capture/cap_seg.h"
#include "../runtime/util/rs_hash.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define PATH "fuzz/s1.mp4.seg"

static void refused(const rs_err *err, int code)
{
    if (err->code != code || strncmp(err->msg, PATH ": ", strlen(PATH) + 2) != 0)
        abort();
}

static bool same(const cap_seg_info *a, const cap_seg_info *b)
{
    return !strcmp(a->key, b->key) && !strcmp(a->format, b->format) && a->w == b->w && a->h == b->h &&
           a->first == b->first && a->end == b->end && a->frames == b->frames && a->bytes == b->bytes &&
           a->crc == b->crc && a->has_hashes == b->has_hashes && (!a->has_hashes || a->hashes_fnv == b->hashes_fnv) &&
           a->has_replay == b->has_replay && (!a->has_replay || a->replay_fnv == b->replay_fnv);
}

static void manifest(const char *text)
{
    cap_seg_info m, again;
    rs_err err = {0};
    if (!cap_seg_manifest_parse(text, PATH, &m, &err)) {
        refused(&err, CAP_ERR_SEG_MANIFEST);
        return;
    }
    if (!cap_seg_key_ok(m.key) || m.w <= 0 || m.h <= 0 || m.end <= m.first || m.frames != m.end - m.first ||
        m.bytes < m.frames)
        abort();
    char out[1024], out2[1024];
    int n = cap_seg_manifest_format(&m, out, sizeof out);
    if (n <= 0 || (size_t)n >= sizeof out || !cap_seg_manifest_parse(out, PATH, &again, &err) || !same(&m, &again))
        abort();
    if (cap_seg_manifest_format(&again, out2, sizeof out2) != n || memcmp(out, out2, (size_t)n) != 0)
        abort();
}

static void hashes(const char *text, size_t len, uint64_t first, uint64_t end)
{
    uint64_t fnv = 0;
    rs_err err = {0};
    if (!cap_seg_hashes_parse(text, len, PATH, first, end, &fnv, &err)) {
        refused(&err, CAP_ERR_SEG_HASHES);
        return;
    }
    if (fnv != rs_fnv1a64(text, len))
        abort();
    /* the text is the list's grammar and nothing else */
    size_t o = 0;
    for (uint64_t t = first; t != end; t++) {
        char num[24];
        int k = snprintf(num, sizeof num, "%" PRIu64 " ", t);
        if (len - o < (size_t)k + 17 || memcmp(text + o, num, (size_t)k) != 0)
            abort();
        o += (size_t)k;
        for (int i = 0; i < 16; i++, o++)
            if (!strchr("0123456789abcdef", text[o]) || !text[o])
                abort();
        if (text[o++] != '\n')
            abort();
    }
    if (o != len)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    uint8_t mode = data[0];
    data++, size--;
    if (!(mode & 1)) {
        char *text = malloc(size + 1); /* the parser's text is NUL-terminated, as rs_read_file's */
        memcpy(text, data, size);
        text[size] = 0;
        manifest(text);
        free(text);
        return 0;
    }
    size_t head = mode & 2 ? 8 : 1;
    if (size < head + (mode & 4 ? 1 : 0))
        return 0;
    uint64_t first = 0;
    for (size_t i = 0; i < head; i++)
        first = first << 8 | data[i];
    data += head, size -= head;
    uint64_t count = 0;
    if (mode & 4) {
        count = data[0];
        data++, size--;
    } else {
        for (size_t i = 0; i < size; i++)
            count += data[i] == '\n';
    }
    char *text = malloc(size + 1);
    memcpy(text, data, size);
    text[size] = 0;
    hashes(text, size, first, first + count);
    free(text);
    return 0;
}
