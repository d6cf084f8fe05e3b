/* hls: a stream's index files and playlists (capture/cap_hls.h).  The
 * cutting itself runs through the real binary in test_segments.sh
 * (hls_pieces) and the service's tests (test_stream.sh).
 *   build/tests/test_hls [index_roundtrip|index_refusals|playlist|piece_check] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../capture/cap_hls.h"
#include "../runtime/util/rs_hash.h"
#include "t.h"

static const char good[] = "ringside-hls 1\nunit 120 400\n"
                           "piece 120 120 1000 0123456789abcdef\n"
                           "piece 240 120 2000 fedcba9876543210\n"
                           "piece 360 40 500 0000000000000001\n";

static void t_index_roundtrip(void)
{
    cap_hls_index ix;
    rs_err err = {0};
    T_ASSERTF(cap_hls_index_parse(good, "u120.idx", &ix, &err), "%s", err.msg);
    T_ASSERT(ix.first == 120 && ix.end == 400 && ix.n == 3);
    T_ASSERT(ix.p[1].tick == 240 && ix.p[1].frames == 120 && ix.p[1].bytes == 2000 && ix.p[1].fnv == 0xfedcba9876543210ull);
    char text[512];
    int n = cap_hls_index_format(&ix, text, sizeof text);
    T_ASSERT(n == (int)strlen(good) && !strcmp(text, good));
    T_EQ(cap_hls_index_format(&ix, NULL, 0), n); /* the length it needs */
    cap_hls_index_free(&ix);
    /* many pieces: past the first allocation */
    cap_hls_index big = {.first = 0, .end = 300 * 120, .n = 300, .p = calloc(300, sizeof(cap_hls_piece))};
    for (int i = 0; i < 300; i++)
        big.p[i] = (cap_hls_piece){.tick = (uint64_t)i * 120, .frames = 120, .bytes = 7, .fnv = (uint64_t)i};
    n = cap_hls_index_format(&big, NULL, 0);
    char *t2 = malloc((size_t)n + 1);
    cap_hls_index_format(&big, t2, (size_t)n + 1);
    T_ASSERTF(cap_hls_index_parse(t2, "big", &ix, &err), "%s", err.msg);
    T_ASSERT(ix.n == 300 && ix.p[299].fnv == 299);
    cap_hls_index_free(&ix);
    cap_hls_index_free(&big);
    free(t2);
}

static void t_index_refusals(void)
{
    /* each: one edit of the good index, and the line the message names */
    const char *bad[][2] = {
        {"ringside-hls 2\nunit 120 400\n", "line 1"},
        {"ringside-hls 1\nunit 400 120\n", "line 2"},
        {"ringside-hls 1\nunit 120 120\n", "line 2"},
        {"ringside-hls 1\nunit 0120 400\n", "line 2"},
        {"ringside-hls 1\nunit 120 400\npiece 120 120 1000 0123456789abcdef\n", "end at tick 240"},
        {"ringside-hls 1\nunit 120 400\npiece 121 279 1000 0123456789abcdef\n", "line 3"},   /* not at the unit's start */
        {"ringside-hls 1\nunit 120 400\npiece 120 281 1000 0123456789abcdef\n", "line 3"},   /* past the unit's end */
        {"ringside-hls 1\nunit 120 400\npiece 120 0 1000 0123456789abcdef\n", "line 3"},     /* empty */
        {"ringside-hls 1\nunit 120 400\npiece 120 280 0 0123456789abcdef\n", "line 3"},      /* no bytes */
        {"ringside-hls 1\nunit 120 400\npiece 120 280 1000 0123456789ABCDEF\n", "line 3"},   /* upper-case hex */
        {"ringside-hls 1\nunit 120 400\npiece 120 280 1000 0123456789abcde\n", "line 3"},    /* 15 digits */
        {"ringside-hls 1\nunit 120 400\npiece 120 280 1000 0123456789abcdef", "line 3"},     /* no newline */
        {"ringside-hls 1\nunit 120 400\npiece 120 280 1000 0123456789abcdef\nextra\n", "line 4"},
        {"ringside-hls 1\nunit 120 99999999999999999999\n", "line 2"},                        /* overflow */
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        cap_hls_index ix;
        rs_err err = {0};
        T_ASSERTF(!cap_hls_index_parse(bad[i][0], "u120.idx", &ix, &err), "case %zu accepted", i);
        T_ASSERTF(strstr(err.msg, "u120.idx") && strstr(err.msg, bad[i][1]), "case %zu: '%s' (want '%s')", i, err.msg,
                  bad[i][1]);
        T_ASSERT(ix.p == NULL && ix.n == 0);
    }
}

static void t_playlist(void)
{
    cap_hls_piece a[] = {{0, 120, 1, 1}, {120, 100, 1, 1}}, b[] = {{220, 150, 1, 1}, {370, 1, 1, 1}};
    cap_hls_index units[] = {{0, 220, 2, a}, {220, 371, 2, b}};
    size_t len;
    char *p = cap_hls_playlist(units, 2, false, "stream/", &len);
    T_ASSERT(p && len == strlen(p));
    /* 150 frames is 2.5 s, rounded to 3: the target grows to cover it */
    T_ASSERTF(!strcmp(p, "#EXTM3U\n#EXT-X-VERSION:7\n#EXT-X-TARGETDURATION:3\n#EXT-X-MEDIA-SEQUENCE:0\n"
                         "#EXT-X-PLAYLIST-TYPE:EVENT\n#EXT-X-INDEPENDENT-SEGMENTS\n"
                         "#EXTINF:2.000000,\nstream/0.ts\n#EXTINF:1.666666,\nstream/120.ts\n"
                         "#EXTINF:2.500000,\nstream/220.ts\n#EXTINF:0.016666,\nstream/370.ts\n"),
              "%s", p);
    free(p);
    p = cap_hls_playlist(units, 1, true, "t", &len);
    T_ASSERT(p && strstr(p, "#EXT-X-TARGETDURATION:2\n") && strstr(p, "t120.ts\n#EXT-X-ENDLIST\n") && !strstr(p, "220"));
    free(p);
    p = cap_hls_playlist(NULL, 0, false, "x", &len); /* nothing yet: a valid playlist without pieces */
    T_ASSERT(p && !strstr(p, "EXTINF") && !strstr(p, "ENDLIST"));
    free(p);
}

static void t_piece_check(void)
{
    char dir[] = "/tmp/test_hls_XXXXXX";
    T_ASSERT(mkdtemp(dir));
    char path[128];
    snprintf(path, sizeof path, "%s/t240.ts", dir);
    const char bytes[] = "abcdefgh";
    FILE *f = fopen(path, "wb");
    fwrite(bytes, 1, 8, f);
    fclose(f);
    cap_hls_piece p = {.tick = 240, .frames = 120, .bytes = 8, .fnv = rs_fnv1a64(bytes, 8)};
    rs_err err = {0};
    uint8_t *data = NULL;
    T_ASSERTF(cap_hls_piece_check(dir, &p, &data, &err), "%s", err.msg);
    T_ASSERT(data && !memcmp(data, bytes, 8));
    free(data);
    p.fnv ^= 1; /* one bit of the index */
    T_ASSERT(!cap_hls_piece_check(dir, &p, NULL, &err) && strstr(err.msg, "not the bytes of"));
    p.fnv ^= 1, p.bytes = 9;
    T_ASSERT(!cap_hls_piece_check(dir, &p, NULL, &err) && strstr(err.msg, "not the size of"));
    p.tick = 360; /* no such file */
    T_ASSERT(!cap_hls_piece_check(dir, &p, NULL, &err) && strstr(err.msg, "t360.ts"));
    /* an index file: none, good, bad */
    cap_hls_index ix;
    T_EQ(cap_hls_index_read(dir, 120, &ix, &err), 0);
    snprintf(path, sizeof path, "%s/u120.idx", dir);
    f = fopen(path, "w");
    fputs(good, f);
    fclose(f);
    T_EQ(cap_hls_index_read(dir, 120, &ix, &err), 1);
    T_EQ(ix.n, 3);
    cap_hls_index_free(&ix);
    char other[160];
    snprintf(other, sizeof other, "%s/u0.idx", dir);
    T_ASSERT(rename(path, other) == 0);
    T_EQ(cap_hls_index_read(dir, 0, &ix, &err), -1); /* names unit 120 */
    T_CONTAINS(err.msg, "another unit");
    unlink(other);
    snprintf(path, sizeof path, "%s/t240.ts", dir);
    unlink(path);
    rmdir(dir);
}

T_MAIN({"index_roundtrip", t_index_roundtrip}, {"index_refusals", t_index_refusals}, {"playlist", t_playlist},
       {"piece_check", t_piece_check})
