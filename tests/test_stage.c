/* runtime/render/r_stage: stage description files. */
#include <glob.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../runtime/game/g_game.h"
#include "../runtime/render/r_stage.h"
#include "../runtime/util/rs_file.h"
#include "t.h"

/* Every key, none at its default. */
static const char full[] = "# a stage with every key set\n"
                           "name = full_stage-2\n"
                           "game = harbor\n"
                           "environment = /data/sky/night sky.HDR\n"
                           "environment_rotate = -90.5\n"
                           "environment_scale = 2.5\n"
                           "sky_zenith = 0.1 0.2 0.3\n"
                           "sky_horizon = 0.4 0.5 0.6\n"
                           "ground = 0.7 0.8 0.9\n"
                           "sun = no\n"
                           "sun_direction = 0 2 0\n"
                           "sun_color = 1 2 3\n"
                           "sun_intensity = 7.5\n"
                           "sun_size = 1.5\n"
                           "key_light = 0 0 -3  1 0.5 0.25  9 45\n"
                           "counter_light = 3 4 0  0.1 0.2 0.3  0.5 0.5\n"
                           "key_area = 40\n"
                           "ring_color = 0.1 0.2 1\n"
                           "exposure = 0.5\n"
                           "gamma = 1.8\n"
                           "saturation = 0\n"
                           "bloom = 2\n"
                           "bloom_threshold = 4\n"
                           "flare = off\n"
                           "shadows = false\n"
                           "hdr_format = r11g11b10f\n"
                           "water = no\n"
                           "snow = 0\n"
                           "fog = off\n"
                           "holes = false\n";

static bool parse(r_stage *st, const char *path, const char *text, rs_err *e)
{
    return r_stage_parse(st, path, text, strlen(text), e);
}

static void parse_ok(r_stage *st, const char *text)
{
    rs_err e = {0};
    T_ASSERTF(parse(st, "t.stage", text, &e), "%s", e.msg);
}

/* Parses text expecting failure with code; returns the message. */
static const char *parse_bad(const char *text, int code)
{
    static rs_err e;
    r_stage st;
    rs_err_clear(&e);
    T_ASSERTF(!parse(&st, "stages/x.stage", text, &e), "accepted: %s", text);
    T_ASSERTF(e.code == code, "%s, want %s: %s", r_stage_error_text(e.code), r_stage_error_text(code), e.msg);
    return e.msg;
}

static bool feq(float a, float b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static bool veq(const float *a, const float *b, int n)
{
    return memcmp(a, b, (size_t)n * sizeof *a) == 0;
}

static bool light_eq(const r_paint_light *a, const r_paint_light *b)
{
    return veq(a->dir, b->dir, 3) && veq(a->color, b->color, 3) && feq(a->intensity, b->intensity) &&
           feq(a->size_deg, b->size_deg);
}

/* The first field that differs (bit for bit), or NULL. */
static const char *stage_diff(const r_stage *a, const r_stage *b)
{
#define D(cond, name)                                                                                                  \
    if (!(cond))                                                                                                       \
        return name;
    D(!strcmp(a->name, b->name), "name");
    D(!strcmp(a->game, b->game), "game");
    D(a->game_index == b->game_index, "game_index");
    D(!strcmp(a->env_path, b->env_path), "env_path");
    D(feq(a->env_rotate_deg, b->env_rotate_deg), "env_rotate_deg");
    D(feq(a->env_scale, b->env_scale), "env_scale");
    D(veq(a->sky_zenith, b->sky_zenith, 3), "sky_zenith");
    D(veq(a->sky_horizon, b->sky_horizon, 3), "sky_horizon");
    D(veq(a->ground, b->ground, 3), "ground");
    D(a->sun == b->sun, "sun");
    D(veq(a->sun_dir, b->sun_dir, 3), "sun_dir");
    D(veq(a->sun_color, b->sun_color, 3), "sun_color");
    D(feq(a->sun_intensity, b->sun_intensity), "sun_intensity");
    D(feq(a->sun_size_deg, b->sun_size_deg), "sun_size_deg");
    D(light_eq(&a->key, &b->key), "key");
    D(light_eq(&a->counter, &b->counter), "counter");
    D(feq(a->key_area_deg, b->key_area_deg), "key_area_deg");
    D(veq(a->ring_color, b->ring_color, 3), "ring_color");
    D(feq(a->exposure, b->exposure), "exposure");
    D(feq(a->gamma, b->gamma), "gamma");
    D(feq(a->saturation, b->saturation), "saturation");
    D(feq(a->bloom, b->bloom), "bloom");
    D(feq(a->bloom_threshold, b->bloom_threshold), "bloom_threshold");
    D(a->flare == b->flare, "flare");
    D(a->shadows == b->shadows, "shadows");
    D(a->hdr_format == b->hdr_format, "hdr_format");
    D(a->water == b->water && a->snow == b->snow && a->fog == b->fog && a->holes == b->holes, "effects");
#undef D
    return NULL;
}

static float len3(const float *v)
{
    return sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

static void vec_is(const float *v, float x, float y, float z)
{
    T_ASSERTF(v[0] == x && v[1] == y && v[2] == z, "(%.9g %.9g %.9g), want (%.9g %.9g %.9g)", v[0], v[1], v[2], x, y,
              z);
}

/* dir is unit length and points along (x, y, z) */
static void dir_is(const float *v, double x, double y, double z)
{
    double l = sqrt(x * x + y * y + z * z);
    T_ASSERTF(fabsf(len3(v) - 1) < 1e-6f, "length %.9g", len3(v));
    T_ASSERTF(fabs(v[0] - x / l) < 1e-6 && fabs(v[1] - y / l) < 1e-6 && fabs(v[2] - z / l) < 1e-6,
              "(%.9g %.9g %.9g) is not along (%g %g %g)", v[0], v[1], v[2], x, y, z);
}

static void t_defaults(void)
{
    r_stage d;
    r_stage_defaults(&d);
    T_ASSERT(!strcmp(d.name, "default") && !strcmp(d.game, g_stages[0].name) && d.game_index == 0);
    T_ASSERT(d.env_path[0] == 0);
    T_ASSERT(d.env_rotate_deg == 0 && d.env_scale == 1);
    vec_is(d.sky_zenith, 0.25f, 0.45f, 0.90f);
    vec_is(d.sky_horizon, 0.9f, 0.85f, 0.8f);
    vec_is(d.ground, 0.12f, 0.10f, 0.08f);
    T_ASSERT(d.sun);
    dir_is(d.sun_dir, -0.4, 0.55, 0.35);
    vec_is(d.sun_color, 1, 0.95f, 0.85f);
    T_ASSERT(d.sun_intensity == 6 && d.sun_size_deg == 0.53f);
    dir_is(d.key.dir, 0.5, 0.6, 0.6);
    vec_is(d.key.color, 1, 0.9f, 0.8f);
    T_ASSERT(d.key.intensity == 4 && d.key.size_deg == 12);
    dir_is(d.counter.dir, -0.6, 0.3, -0.5);
    vec_is(d.counter.color, 0.4f, 0.5f, 0.8f);
    T_ASSERT(d.counter.intensity == 2 && d.counter.size_deg == 20);
    T_ASSERT(d.key_area_deg == 25);
    vec_is(d.ring_color, 0.55f, 0.42f, 0.28f);
    T_ASSERT(d.exposure == 1 && d.gamma == 2.2f && d.saturation == 1 && d.bloom == 0.35f && d.bloom_threshold == 1);
    T_ASSERT(d.flare && d.shadows && d.hdr_format == R_HDR_RGBA16F);
    T_ASSERT(!d.water && !d.snow && !d.fog && !d.holes);

    /* a file with only the required keys is the defaults */
    r_stage st;
    parse_ok(&st, "name = default\ngame = dojo\n");
    const char *diff = stage_diff(&st, &d);
    T_ASSERTF(!diff, "minimal file differs from the defaults in %s", diff);
    /* and writing every default out explicitly changes nothing */
    parse_ok(&st, "name = default\ngame = dojo\nenvironment = procedural\nenvironment_rotate = 0\n"
                  "environment_scale = 1\nsky_zenith = 0.25 0.45 0.90\nsky_horizon = 0.9 0.85 0.8\n"
                  "ground = 0.12 0.10 0.08\nsun = yes\nsun_direction = -0.4 0.55 0.35\nsun_color = 1 0.95 0.85\n"
                  "sun_intensity = 6\nsun_size = 0.53\nkey_light = 0.5 0.6 0.6 1 0.9 0.8 4 12\n"
                  "counter_light = -0.6 0.3 -0.5 0.4 0.5 0.8 2 20\nkey_area = 25\nring_color = 0.55 0.42 0.28\n"
                  "exposure = 1\ngamma = 2.2\nsaturation = 1\nbloom = 0.35\nbloom_threshold = 1\nflare = yes\n"
                  "shadows = yes\nhdr_format = rgba16f\nwater = no\nsnow = no\nfog = no\nholes = no\n");
    diff = stage_diff(&st, &d);
    T_ASSERTF(!diff, "explicit defaults differ in %s", diff);
}

static void t_every_key(void)
{
    r_stage st;
    parse_ok(&st, full);
    T_ASSERT(!strcmp(st.name, "full_stage-2"));
    T_ASSERT(!strcmp(st.game, "harbor") && st.game_index == 1);
    T_ASSERT(!strcmp(st.env_path, "/data/sky/night sky.HDR"));
    T_ASSERT(st.env_rotate_deg == -90.5f && st.env_scale == 2.5f);
    vec_is(st.sky_zenith, 0.1f, 0.2f, 0.3f);
    vec_is(st.sky_horizon, 0.4f, 0.5f, 0.6f);
    vec_is(st.ground, 0.7f, 0.8f, 0.9f);
    T_ASSERT(!st.sun);
    vec_is(st.sun_dir, 0, 1, 0);
    vec_is(st.sun_color, 1, 2, 3);
    T_ASSERT(st.sun_intensity == 7.5f && st.sun_size_deg == 1.5f);
    vec_is(st.key.dir, 0, 0, -1);
    vec_is(st.key.color, 1, 0.5f, 0.25f);
    T_ASSERT(st.key.intensity == 9 && st.key.size_deg == 45);
    vec_is(st.counter.dir, 0.6f, 0.8f, 0);
    vec_is(st.counter.color, 0.1f, 0.2f, 0.3f);
    T_ASSERT(st.counter.intensity == 0.5f && st.counter.size_deg == 0.5f);
    T_ASSERT(st.key_area_deg == 40);
    vec_is(st.ring_color, 0.1f, 0.2f, 1);
    T_ASSERT(st.exposure == 0.5f && st.gamma == 1.8f && st.saturation == 0 && st.bloom == 2 &&
             st.bloom_threshold == 4);
    T_ASSERT(!st.flare && !st.shadows && st.hdr_format == R_HDR_R11G11B10F);
    T_ASSERT(!st.water && !st.snow && !st.fog && !st.holes);

    /* every spelling of a boolean */
    static const char *const yes[] = {"yes", "true", "on", "1"}, *const no[] = {"no", "false", "off", "0"};
    for (int i = 0; i < 4; i++) {
        char text[128];
        snprintf(text, sizeof text, "name = a\ngame = temple\nflare = %s\nshadows = %s\n", no[i], yes[i]);
        parse_ok(&st, text);
        T_ASSERT(!st.flare && st.shadows && st.game_index == 2);
    }
    parse_ok(&st, "name = a\ngame = dojo\nhdr_format = rgba16f\nsun_direction = 0 0 -0.5\n");
    T_ASSERT(st.hdr_format == R_HDR_RGBA16F);
    vec_is(st.sun_dir, 0, 0, -1);
}

static void t_layout(void)
{
    r_stage st;
    /* comments anywhere, blank and whitespace-only lines, CRLF, tabs, no final newline */
    parse_ok(&st, "# header\r\n\r\n   \t\r\n\tname\t=\tdojo_b   # trailing comment\r\n"
                  "game=dojo#no spaces\r\n#gamma = 99\r\n  exposure =   2  \r\n"
                  "environment = my sky.exr # a path with a space\r\nsaturation = 3");
    T_ASSERT(!strcmp(st.name, "dojo_b") && st.game_index == 0);
    T_ASSERT(st.gamma == 2.2f && st.exposure == 2 && st.saturation == 3);
    T_ASSERT(!strcmp(st.env_path, "my sky.exr"));
    /* old Mac line ends are not line ends: the value is refused, not misread */
    T_CONTAINS(parse_bad("name = a\rgame = dojo\n", R_STAGE_ERR_VALUE), "stages/x.stage:1: name:");
    parse_ok(&st, "\n\n\nname = b\n\n\ngame = temple\n\n");
    T_ASSERT(st.game_index == 2);
    /* a UTF-8 byte-order mark before the first key, and only there */
    parse_ok(&st, "\xef\xbb\xbfname = bom\r\ngame = harbor\r\n");
    T_ASSERT(!strcmp(st.name, "bom") && st.game_index == 1);
    T_CONTAINS(parse_bad("name = a\n\xef\xbb\xbfgame = dojo\n", R_STAGE_ERR_UNKNOWN_KEY), "stages/x.stage:2: unknown key");
}

static void t_syntax_errors(void)
{
    const char *m;
    m = parse_bad("name = a\ngame = dojo\n\n   sun yes\n", R_STAGE_ERR_SYNTAX);
    T_CONTAINS(m, "stages/x.stage:4: missing '=' (expected key = value)");
    T_CONTAINS(m, "'sun yes'");
    m = parse_bad("# c\n = 3\n", R_STAGE_ERR_SYNTAX);
    T_CONTAINS(m, "stages/x.stage:2: missing key before '='");
    m = parse_bad("name = a\ngame = dojo\nsunn = yes\n", R_STAGE_ERR_UNKNOWN_KEY);
    T_CONTAINS(m, "stages/x.stage:3: unknown key 'sunn' (did you mean 'sun'?)");
    m = parse_bad("Gamma = 2\n", R_STAGE_ERR_UNKNOWN_KEY);
    T_CONTAINS(m, "stages/x.stage:1: unknown key 'Gamma' (did you mean 'gamma'?)");
    m = parse_bad("name = a\nwidget = 3\n", R_STAGE_ERR_UNKNOWN_KEY);
    T_CONTAINS(m, "stages/x.stage:2: unknown key 'widget' (keys are listed in docs/stages.md)");
    m = parse_bad("name = a\ngamma = 2\n# x\ngame = dojo\n\n\n\n\ngamma = 2\n", R_STAGE_ERR_DUPLICATE_KEY);
    T_CONTAINS(m, "stages/x.stage:9: duplicate key 'gamma' (first on line 2)");
    /* a duplicate is refused even when both values agree or the first was a default */
    m = parse_bad("name = a\nname = a\n", R_STAGE_ERR_DUPLICATE_KEY);
    T_CONTAINS(m, "stages/x.stage:2: duplicate key 'name' (first on line 1)");

    static const char nul[] = "name = a\ngame = d\0ojo\n";
    rs_err e = {0};
    r_stage st;
    T_ASSERT(!r_stage_parse(&st, "stages/x.stage", nul, sizeof nul - 1, &e));
    T_EQ(e.code, R_STAGE_ERR_SYNTAX);
    T_CONTAINS(e.msg, "stages/x.stage:2: NUL byte at column 9");
    /* the text need not be NUL-terminated: only len bytes are read */
    T_ASSERT(r_stage_parse(&st, "p", "name = a\ngame = dojoXXXX", 20, &e));
    T_ASSERT(!strcmp(st.game, "dojo"));

    char *big = malloc(R_STAGE_MAX_BYTES + 2);
    memset(big, '#', R_STAGE_MAX_BYTES + 1);
    T_ASSERT(!r_stage_parse(&st, "big.stage", big, R_STAGE_MAX_BYTES + 1, &e));
    T_EQ(e.code, R_STAGE_ERR_FILE);
    T_CONTAINS(e.msg, "big.stage: 65537 bytes is larger than the 65536-byte limit");
    free(big);
}

static void t_missing_required(void)
{
    const char *m = parse_bad("name = a\n", R_STAGE_ERR_MISSING_KEY);
    T_CONTAINS(m, "stages/x.stage: missing required key 'game'");
    m = parse_bad("# nothing\ngame = dojo\n", R_STAGE_ERR_MISSING_KEY);
    T_CONTAINS(m, "stages/x.stage: missing required key 'name'");
    m = parse_bad("", R_STAGE_ERR_MISSING_KEY);
    T_CONTAINS(m, "stages/x.stage: missing required key 'name'");
}

static void t_value_errors(void)
{
    enum { VAL = R_STAGE_ERR_VALUE, RNG = R_STAGE_ERR_RANGE };
    static const struct {
        const char *line, *want;
        int code;
    } cases[] = {
        {"sun_intensity = abc", "sun_intensity: expected a number in 0..65504, got 'abc'", VAL},
        {"sun_intensity =", "sun_intensity: expected a number in 0..65504, got ''", VAL},
        {"gamma = 2.2.2", "gamma: expected a number in 0.1..10, got '2.2.2'", VAL},
        {"gamma = 2 2", "gamma: expected a number in 0.1..10, got '2 2'", VAL},
        {"exposure = 0.0009", "exposure: expected a number in 0.001..1000, got '0.0009'", RNG},
        {"environment_rotate = -361", "environment_rotate: expected a number in -360..360, got '-361'", RNG},
        {"sun_size = 0.04", "sun_size: expected a number in 0.05..20, got '0.04'", RNG},
        {"key_area = 0.5", "key_area: expected a number in 1..90, got '0.5'", RNG},
        {"saturation = -0.1", "saturation: expected a number in 0..10, got '-0.1'", RNG},
        {"name = Dojo", "name: expected 1 to 31 characters of a-z 0-9 _ -, got 'Dojo'", VAL},
        {"name = a b", "name: expected 1 to 31 characters", VAL},
        {"name = abcdefghijklmnopqrstuvwxyz012345", "name: expected 1 to 31 characters", VAL},
        {"game = arena", "game: expected a game stage (dojo, harbor, temple, shallows, snowfield, mistvale, plaza or quarry), got 'arena'", VAL},
        {"game = Dojo", "game: expected a game stage (dojo, harbor, temple, shallows, snowfield, mistvale, plaza or quarry), got 'Dojo'", VAL},
        {"sky_zenith = 0.1 0.2", "sky_zenith: expected 3 numbers (r g b), got 2: '0.1 0.2'", VAL},
        {"sky_horizon = 0.1 0.2 0.3 0.4", "sky_horizon: expected 3 numbers (r g b), got 4", VAL},
        {"ground = 0.1 x 0.3", "ground: g: expected a number in 0..65504, got 'x'", VAL},
        {"ring_color = 0.5 0.5 1.01", "ring_color: b: expected a number in 0..1, got '1.01'", RNG},
        {"sun_direction = 0 0 0", "sun_direction: expected a direction x y z that is not all zero, got '0 0 0'", VAL},
        {"sun_direction = 1e-50 0 0", "sun_direction: expected a direction x y z that is not all zero", VAL},
        {"sun_direction = 1 2", "sun_direction: expected 3 numbers (x y z), got 2", VAL},
        {"sun_direction = 1 nan 2", "sun_direction: y: expected a number in -65504..65504, got 'nan'", VAL},
        {"sun = maybe", "sun: expected yes or no (or true/false, on/off, 1/0), got 'maybe'", VAL},
        {"shadows = YES", "shadows: expected yes or no", VAL},
        {"flare =", "flare: expected yes or no (or true/false, on/off, 1/0), got ''", VAL},
        {"hdr_format = rgba8", "hdr_format: expected rgba16f or r11g11b10f, got 'rgba8'", VAL},
        {"key_light = 1 1 1 1 1 1 1", "key_light: expected 8 numbers (x y z r g b intensity size_deg), got 7", VAL},
        {"key_light = 1 1 1 1 1 1 1 1 1", "key_light: expected 8 numbers (x y z r g b intensity size_deg), got 9", VAL},
        {"key_light = 1 1 1 1 1 1 1 91", "key_light: size_deg: expected a number in 0.5..90, got '91'", RNG},
        {"counter_light = 1 1 1 1 1 1 1 0.4", "counter_light: size_deg: expected a number in 0.5..90, got '0.4'", RNG},
        {"counter_light = 1 1 1 1 -1 1 1 1", "counter_light: g: expected a number in 0..65504, got '-1'", RNG},
        {"key_light = 1 1 1 1 1 1 65505 1", "key_light: intensity: expected a number in 0..65504, got '65505'", RNG},
        {"key_light = 0 0 0 1 1 1 1 1", "key_light: expected a direction x y z that is not all zero", VAL},
        {"environment = sky.png", "environment: expected 'procedural' or an .hdr or .exr file, got 'sky.png'", VAL},
        {"environment = .hdr", "environment: expected 'procedural' or an .hdr or .exr file", VAL},
        {"environment = Procedural", "environment: expected 'procedural' or an .hdr or .exr file", VAL},
        {"holes = maybe", "holes: expected yes or no (or true/false, on/off, 1/0), got 'maybe'", VAL},
        {"afterimage = blur", "afterimage: expected view, world or off, got 'blur'", VAL},
        {"afterimage = View", "afterimage: expected view, world or off, got 'View'", VAL},
        {"afterimage_stretch = 9", "afterimage_stretch: expected a number in 1..8, got '9'", RNG},
        {"buildings = 49", "buildings: expected a whole number in 0..48, got '49'", RNG},
        {"buildings = 2.5", "buildings: expected a whole number in 0..48, got '2.5'", VAL},
        {"buildings = +7", "buildings: expected a whole number in 0..48, got '+7'", VAL},
        {"buildings = -1", "buildings: expected a whole number in 0..48, got '-1'", VAL},
        {"buildings_seed = 99999999999999999999", "buildings_seed: expected a whole number in 0..16777216, got '99999999999999999999'", RNG},
        {"afterimage_speed = -1", "afterimage_speed: expected a number in 0..1000, got '-1'", RNG},
        {"water = perhaps", "water: expected yes or no", VAL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[256], want[256];
        /* the error comes before the check for required keys */
        snprintf(text, sizeof text, "# comment\n\n  # another\n\n%s\nname = a\ngame = dojo\n", cases[i].line);
        snprintf(want, sizeof want, "stages/x.stage:5: %s", cases[i].want);
        T_CONTAINS(parse_bad(text, cases[i].code), want);
    }
    /* a value in a message is cut and stripped of control bytes */
    char text[400] = "name = ";
    memset(text + 7, 'q', 300);
    const char *m = parse_bad(text, R_STAGE_ERR_VALUE);
    T_CONTAINS(m, "got 'qqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqqq...'");
    m = parse_bad("gamma = 1\x1b[31m\n", R_STAGE_ERR_VALUE);
    T_CONTAINS(m, "got '1?[31m'");
}

static void t_bounds(void)
{
    static const char *const ok[] = {
        "sun_intensity = 65504", "sun_intensity = 0", "sun_intensity = -0", "environment_scale = 65504",
        "bloom_threshold = 6.5504e4", "sky_zenith = 65504 0 65504", "sun_color = 0 65504 0",
        "environment_rotate = -360", "environment_rotate = 360", "exposure = 0.001", "exposure = 1000",
        "gamma = 0.1", "gamma = 10", "sun_size = 0.05", "sun_size = 20", "key_area = 1", "key_area = 90",
        "ring_color = 0 1 1", "bloom = 10", "saturation = 10", "key_light = 65504 -65504 1 65504 0 0 65504 90",
        "counter_light = 0 0 1e-30 0 0 0 0 0.5", "sun_direction = -65504 -65504 -65504", "gamma = +2",
        "gamma = 0x1p1", "sun_intensity = 1e-400",
    };
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        char text[256];
        snprintf(text, sizeof text, "name = a\ngame = dojo\n%s\n", ok[i]);
        r_stage st;
        rs_err e = {0};
        T_ASSERTF(parse(&st, "b.stage", text, &e), "%s: %s", ok[i], e.msg);
    }
    static const char *const refused[] = {
        "sun_intensity = 65504.1", "sun_intensity = -0.0001", "environment_scale = 65504.01",
        "sky_zenith = 0 65504.1 0", "bloom_threshold = 1e39", "environment_rotate = 360.001", "exposure = 1000.5",
        "gamma = 10.0001", "sun_size = 20.01", "key_area = 90.01", "bloom = 10.5", "ring_color = 0 0 1.0000001",
        "sun_direction = 65505 0 0", "key_light = 1 1 1 65504.1 0 0 1 1",
        "sun_intensity = nan", "sun_intensity = inf", "sun_intensity = -inf", "sun_intensity = infinity",
        "sun_intensity = 1e400", "sun_intensity = NAN", "key_light = inf 1 1 1 1 1 1 1", "gamma = 2f", "gamma = 0x",
        "gamma = 2,5", "gamma = 1e", "gamma = .",
    };
    /* the first of them are numbers out of range; from here on, not numbers at all */
    static const char *const first_not_a_number = "sun_intensity = nan";
    int code = R_STAGE_ERR_RANGE;
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++) {
        char text[256], want[64];
        snprintf(text, sizeof text, "name = a\ngame = dojo\n%s\n", refused[i]);
        snprintf(want, sizeof want, "stages/x.stage:3: %.*s:", (int)strcspn(refused[i], " "), refused[i]);
        if (!strcmp(refused[i], first_not_a_number))
            code = R_STAGE_ERR_VALUE;
        T_CONTAINS(parse_bad(text, code), want);
    }
}

static void t_directions_normalised(void)
{
    r_stage st;
    parse_ok(&st, "name = a\ngame = dojo\nsun_direction = 0 0 5\nkey_light = 3 0 4 1 1 1 1 1\n"
                  "counter_light = 1e-30 1e-30 0 1 1 1 1 1\n");
    vec_is(st.sun_dir, 0, 0, 1);
    dir_is(st.key.dir, 3, 0, 4);
    dir_is(st.counter.dir, 1, 1, 0);
    parse_ok(&st, "name = a\ngame = dojo\nsun_direction = 1 1 1\n");
    dir_is(st.sun_dir, 1, 1, 1);
    /* normalising twice changes nothing, to the bit */
    char text[256];
    snprintf(text, sizeof text, "name = a\ngame = dojo\nsun_direction = %.9g %.9g %.9g\n", st.sun_dir[0],
             st.sun_dir[1], st.sun_dir[2]);
    r_stage again;
    parse_ok(&again, text);
    T_ASSERT(veq(st.sun_dir, again.sun_dir, 3));
}

static void t_environment_path(void)
{
    static const struct {
        const char *path, *value, *want;
    } cases[] = {
        {"stages/dojo.stage", "sky.hdr", "stages/sky.hdr"},
        {"stages/dojo.stage", "env/night sky.EXR", "stages/env/night sky.EXR"},
        {"stages/dojo.stage", "../hdri/a.Hdr", "stages/../hdri/a.Hdr"},
        {"/opt/rs/stages/x.stage", "sky.exr", "/opt/rs/stages/sky.exr"},
        {"/x.stage", "sky.hdr", "/sky.hdr"},
        {"x.stage", "sky.hdr", "sky.hdr"},
        {"stages/dojo.stage", "/abs/sky.hdr", "/abs/sky.hdr"},
        {"stages/dojo.stage", "procedural", ""},
        {"a/b/c.stage", "./d.hdr", "a/b/./d.hdr"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[256];
        snprintf(text, sizeof text, "name = a\ngame = dojo\nenvironment = %s\n", cases[i].value);
        r_stage st;
        rs_err e = {0};
        T_ASSERTF(parse(&st, cases[i].path, text, &e), "%s", e.msg);
        T_ASSERTF(!strcmp(st.env_path, cases[i].want), "%s + %s: got '%s', want '%s'", cases[i].path,
                  cases[i].value, st.env_path, cases[i].want);
    }
    /* the longest path that fits, and one byte more */
    char text[1200], value[1100];
    memset(value, 'p', 1019);
    strcpy(value + 1019, ".hdr"); /* 1023 bytes */
    snprintf(text, sizeof text, "name = a\ngame = dojo\nenvironment = %s\n", value);
    r_stage st;
    rs_err e = {0};
    T_ASSERTF(parse(&st, "x.stage", text, &e), "%s", e.msg);
    T_EQ(strlen(st.env_path), 1023);
    T_ASSERT(!parse(&st, "d/x.stage", text, &e));
    T_EQ(e.code, R_STAGE_ERR_VALUE);
    T_CONTAINS(e.msg, "d/x.stage:3: environment: the path is longer than 1023 bytes");
}

static void round_trip(const r_stage *st, const char *what)
{
    char text[8192], text2[8192];
    int n = r_stage_format(st, text, sizeof text);
    T_ASSERT(n > 0 && (size_t)n < sizeof text);
    T_EQ(strlen(text), n);
    r_stage back;
    rs_err e = {0};
    T_ASSERTF(parse(&back, "/elsewhere/rt.stage", text, &e), "%s: %s\n%s", what, e.msg, text);
    const char *diff = stage_diff(st, &back);
    T_ASSERTF(!diff, "%s: %s differs after format and parse:\n%s", what, diff, text);
    T_EQ(r_stage_format(&back, text2, sizeof text2), n);
    T_ASSERTF(!strcmp(text, text2), "%s: the second write differs", what);
}

/* Random text for a number in lo..hi, sometimes exactly at a bound. */
static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static uint64_t rnd(void)
{
    uint64_t x = rng_state;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return rng_state = x;
}

static double rnd_in(double lo, double hi)
{
    switch (rnd() % 8) {
    case 0:
        return lo;
    case 1:
        return hi;
    default:
        return lo + (hi - lo) * (double)(rnd() >> 11) / 9007199254740992.0;
    }
}

static void t_round_trip(void)
{
    r_stage st;
    r_stage_defaults(&st);
    round_trip(&st, "defaults");
    parse_ok(&st, full);
    round_trip(&st, "every key");
    parse_ok(&st, "name = edge\ngame = temple\nexposure = 0.001\ngamma = 0.1\nsun_size = 0.05\nkey_area = 1\n"
                  "key_light = 1e-30 -1e-30 0 65504 65504 65504 65504 0.5\nenvironment_rotate = -360\n"
                  "sun_intensity = -0\nring_color = 1 1 1\ncounter_light = 0.1 0.2 0.3 0 0 0 0 90\n"
                  "environment = /tmp/a b/c d.EXR # a comment\n");
    T_ASSERT(!strcmp(st.env_path, "/tmp/a b/c d.EXR"));
    round_trip(&st, "edges");

    /* random valid stages, written with 17 digits, parsed, written with 9, parsed */
    for (int it = 0; it < 2000; it++) {
        char text[4096];
        size_t o = 0;
#define P(...) o += (size_t)snprintf(text + o, sizeof text - o, __VA_ARGS__)
        P("name = r%d\ngame = %s\n", it, g_stages[rnd() % G_STAGES].name);
        if (rnd() % 2)
            P("environment = /env/%d %s\n", it, rnd() % 2 ? "x.hdr" : "y.EXR");
        P("environment_rotate = %.17g\n", rnd_in(-360, 360));
        P("environment_scale = %.17g\n", rnd_in(0, 65504));
        static const char *const colors[] = {"sky_zenith", "sky_horizon", "ground", "sun_color"};
        for (int k = 0; k < 4; k++)
            P("%s = %.17g %.17g %.17g\n", colors[k], rnd_in(0, 65504), rnd_in(0, 65504), rnd_in(0, 65504));
        P("ring_color = %.17g %.17g %.17g\n", rnd_in(0, 1), rnd_in(0, 1), rnd_in(0, 1));
        P("sun = %s\nflare = %s\nshadows = %s\n", rnd() % 2 ? "yes" : "no", rnd() % 2 ? "on" : "off",
          rnd() % 2 ? "1" : "0");
        P("sun_direction = %.17g %.17g %.17g\n", rnd_in(-2, 2), rnd_in(-2, 2), 0.01 + rnd_in(0, 100));
        P("sun_intensity = %.17g\nsun_size = %.17g\n", rnd_in(0, 65504), rnd_in(0.05, 20));
        static const char *const lights[] = {"key_light", "counter_light"};
        for (int k = 0; k < 2; k++)
            P("%s = %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", lights[k], rnd_in(-1e3, 1e3),
              rnd_in(-1e3, 1e3), 1e-3 + rnd_in(0, 1e3), rnd_in(0, 65504), rnd_in(0, 65504), rnd_in(0, 65504),
              rnd_in(0, 65504), rnd_in(0.5, 90));
        P("key_area = %.17g\nexposure = %.17g\ngamma = %.17g\n", rnd_in(1, 90), rnd_in(0.001, 1000),
          rnd_in(0.1, 10));
        P("saturation = %.17g\nbloom = %.17g\nbloom_threshold = %.17g\n", rnd_in(0, 10), rnd_in(0, 10),
          rnd_in(0, 65504));
        P("hdr_format = %s\n", rnd() % 2 ? "rgba16f" : "r11g11b10f");
#undef P
        rs_err e = {0};
        T_ASSERTF(parse(&st, "/r/x.stage", text, &e), "iteration %d: %s\n%s", it, e.msg, text);
        char what[32];
        snprintf(what, sizeof what, "random %d", it);
        round_trip(&st, what);
    }
}

static void t_format_snprintf_rules(void)
{
    r_stage st;
    r_stage_defaults(&st);
    char whole[4096], cut[16];
    int n = r_stage_format(&st, whole, sizeof whole);
    T_ASSERT(n > 100);
    T_EQ(r_stage_format(&st, NULL, 0), n);
    memset(cut, 'x', sizeof cut);
    T_EQ(r_stage_format(&st, cut, sizeof cut), n);
    T_EQ(strlen(cut), sizeof cut - 1);
    T_ASSERT(!memcmp(cut, whole, sizeof cut - 1));
    /* every key is written, and the canonical forms */
    T_CONTAINS(whole, "\nname = default\n");
    T_CONTAINS(whole, "\nenvironment = procedural\n");
    T_CONTAINS(whole, "\nsun = yes\n");
    T_CONTAINS(whole, "\nhdr_format = rgba16f\n");
    T_CONTAINS(whole, "\nwater = no\nsnow = no\nfog = no\nholes = no\n");
    T_CONTAINS(whole, "\ngamma = 2.20000005\n");
    static const char *const keys[] = {
        "name", "game", "environment", "environment_rotate", "environment_scale", "sky_zenith", "sky_horizon",
        "ground", "sun", "sun_direction", "sun_color", "sun_intensity", "sun_size", "key_light", "counter_light",
        "key_area", "ring_color", "exposure", "gamma", "saturation", "bloom", "bloom_threshold", "flare",
        "shadows", "hdr_format", "water", "snow", "fog", "holes",
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        char k[64];
        snprintf(k, sizeof k, "\n%s = ", keys[i]);
        T_CONTAINS(whole, k);
    }
}

/* 20000 damaged variants of a valid file: none may crash or read past the
 * text (ASan); each either parses to a stage inside every bound, or fails
 * with a "path:line:" or "path:" message. */
static const char *const junk_lines[] = {
    "sun = maybe", "gamma = 1e400", "key_light = 0 0 0 1 1 1 1 1", "environment = ../x.HDR", "=", "==",
    "name = ", "game = harbor", "# comment", "water = yes", "\xff\xfe gamma = 1", "sun_direction = nan 1 1",
    "hdr_format = r11g11b10f", "ring_color = 1 1 1 1", "fog = no", "environment = procedural",
};

static void check_result(bool ok, const r_stage *st, const rs_err *e, int it)
{
    if (!ok) {
        T_ASSERTF(!strncmp(e->msg, "fuzz/x.stage:", 13), "iteration %d: message '%s'", it, e->msg);
        T_ASSERTF(RS_ERR_MODULE(e->code) == RS_ERR_MOD_R_STAGE && e->code != R_STAGE_ERR_FILE &&
                      e->code != R_STAGE_ERR_GAME,
                  "iteration %d: %s", it, r_stage_error_text(e->code));
        T_ASSERT(!strchr(e->msg, '\n'));
        return;
    }
    size_t n = strlen(st->name);
    T_ASSERT(n >= 1 && n <= 31 && strspn(st->name, "abcdefghijklmnopqrstuvwxyz0123456789_-") == n);
    T_ASSERT(st->game_index >= 0 && st->game_index < G_STAGES && !strcmp(st->game, g_stages[st->game_index].name));
    T_ASSERTF(fabsf(len3(st->sun_dir) - 1) < 1e-5f && fabsf(len3(st->key.dir) - 1) < 1e-5f &&
                  fabsf(len3(st->counter.dir) - 1) < 1e-5f,
              "iteration %d: a direction is not unit length", it);
    T_ASSERT(st->exposure >= 0.001f && st->exposure <= 1000 && st->gamma >= 0.1f && st->gamma <= 10);
    T_ASSERT(st->sun_size_deg >= 0.05f && st->sun_size_deg <= 20 && st->key_area_deg >= 1 && st->key_area_deg <= 90);
    T_ASSERT(st->key.size_deg >= 0.5f && st->key.size_deg <= 90 && st->counter.size_deg >= 0.5f);
    for (int k = 0; k < 3; k++)
        T_ASSERT(st->ring_color[k] >= 0 && st->ring_color[k] <= 1 && st->sky_zenith[k] >= 0 &&
                 st->sky_zenith[k] <= R_HALF_MAX && st->sun_color[k] <= R_HALF_MAX);
    T_ASSERT(!st->holes); /* refused until built */
    if (st->env_path[0] == 0 || st->env_path[0] == '/') {
        char what[32];
        snprintf(what, sizeof what, "fuzz %d", it);
        round_trip(st, what);
    }
}

static void t_randomized(void)
{
    size_t base_len = strlen(full);
    size_t cap = 4 * base_len + 4096;
    char *work = malloc(cap);
    int parsed = 0, failed = 0;
    rng_state = 0x243f6a8885a308d3ull;
    for (int it = 0; it < 20000; it++) {
        memcpy(work, full, base_len);
        size_t len = base_len;
        int ops = 1 + (int)(rnd() % 4);
        for (int op = 0; op < ops; op++) {
            switch (rnd() % 8) {
            case 0: /* flip a byte */
                if (len)
                    work[rnd() % len] ^= (char)(1u << (rnd() % 8));
                break;
            case 1: { /* a byte the parser cares about */
                static const char special[] = " =#\n\r\t\0.-e";
                if (len)
                    work[rnd() % len] = special[rnd() % (sizeof special - 1)];
                break;
            }
            case 2: /* truncate */
                len = len ? (size_t)(rnd() % len) : 0;
                break;
            case 3: { /* insert a known-troublesome line */
                const char *l = junk_lines[rnd() % (sizeof junk_lines / sizeof junk_lines[0])];
                size_t ln = strlen(l), at = len ? rnd() % (len + 1) : 0;
                if (len + ln + 2 > cap)
                    break;
                memmove(work + at + ln + 1, work + at, len - at);
                memcpy(work + at, l, ln);
                work[at + ln] = '\n';
                len += ln + 1;
                break;
            }
            case 4: { /* insert random bytes */
                size_t ln = rnd() % 40, at = len ? rnd() % (len + 1) : 0;
                if (len + ln > cap)
                    break;
                memmove(work + at + ln, work + at, len - at);
                for (size_t k = 0; k < ln; k++)
                    work[at + k] = (char)rnd();
                len += ln;
                break;
            }
            case 5: { /* delete a range */
                if (!len)
                    break;
                size_t at = rnd() % len, ln = rnd() % (len - at + 1);
                memmove(work + at, work + at + ln, len - at - ln);
                len -= ln;
                break;
            }
            case 6: { /* repeat a range (duplicate keys) */
                if (!len)
                    break;
                size_t at = rnd() % len, ln = rnd() % (len - at + 1);
                if (len + ln > cap)
                    break;
                memmove(work + len, work + at, ln);
                len += ln;
                break;
            }
            default: { /* replace one digit: values near and past their bounds */
                if (!len)
                    break;
                size_t at = rnd() % len;
                while (at < len && !(work[at] >= '0' && work[at] <= '9'))
                    at++;
                if (at < len)
                    work[at] = (char)('0' + rnd() % 10);
                break;
            }
            }
        }
        /* an exact-size copy, so reading past len is an ASan error */
        char *text = malloc(len ? len : 1);
        memcpy(text, work, len);
        r_stage st;
        rs_err e = {0};
        bool ok = r_stage_parse(&st, "fuzz/x.stage", text, len, &e);
        check_result(ok, &st, &e, it);
        parsed += ok;
        failed += !ok;
        free(text);
    }
    free(work);
    printf("    %d parsed, %d refused\n", parsed, failed);
    T_ASSERTF(parsed > 500 && failed > 500, "%d parsed, %d refused: the mutations are not exercising both", parsed,
              failed);
}

static void t_shipped_stages(void)
{
    glob_t g;
    T_EQ(glob(RS_SOURCE_DIR "/stages/*.stage", 0, NULL, &g), 0);
    T_ASSERTF(g.gl_pathc >= 4, "%zu stage files", (size_t)g.gl_pathc);
    bool seen[G_STAGES] = {false};
    for (size_t i = 0; i < g.gl_pathc; i++) {
        r_stage st;
        rs_err e = {0};
        T_ASSERTF(r_stage_load(&st, g.gl_pathv[i], &e), "%s", e.msg);
        const char *base = strrchr(g.gl_pathv[i], '/') + 1;
        T_ASSERTF(!strncmp(base, st.name, strlen(st.name)) && !strcmp(base + strlen(st.name), ".stage"),
                  "%s: name is '%s'", g.gl_pathv[i], st.name);
        if (!strcmp(st.name, st.game))
            seen[st.game_index] = true;
    }
    globfree(&g);
    for (int i = 0; i < G_STAGES; i++)
        T_ASSERTF(seen[i], "no stages/%s.stage", g_stages[i].name);

    r_stage st;
    rs_err e = {0};
    T_ASSERTF(r_stage_load(&st, RS_SOURCE_DIR "/stages/harbor.stage", &e), "%s", e.msg);
    T_ASSERT(!st.sun && st.bloom == 0 && st.shadows);
    T_ASSERTF(r_stage_load(&st, RS_SOURCE_DIR "/stages/sunless.stage", &e), "%s", e.msg);
    T_ASSERT(!st.sun && st.bloom == 0 && !st.flare && !st.shadows && st.game_index == 0);
    T_ASSERTF(r_stage_load(&st, RS_SOURCE_DIR "/stages/temple.stage", &e), "%s", e.msg);
    T_ASSERT(st.sun && st.sun_intensity >= 7 && st.sun_dir[1] > 0.7f && st.bloom == 0.5f);
    T_ASSERTF(r_stage_load(&st, RS_SOURCE_DIR "/stages/dojo.stage", &e), "%s", e.msg);
    T_ASSERT(st.sun && st.sun_dir[1] < 0.3f && st.sun_intensity >= 4 && st.sun_intensity <= 6);
}

static void t_for_game(void)
{
    setenv("RINGSIDE_DATA", RS_SOURCE_DIR, 1);
    rs_data_reset();
    for (int i = 0; i < G_STAGES; i++) {
        r_stage st;
        rs_err e = {0};
        T_ASSERTF(r_stage_for_game(&st, i, &e), "%s", e.msg);
        T_EQ(st.game_index, i);
        T_ASSERT(!strcmp(st.name, g_stages[i].name));
    }
    r_stage st;
    rs_err e = {0};
    T_ASSERT(!r_stage_for_game(&st, G_STAGES, &e));
    T_EQ(e.code, R_STAGE_ERR_GAME);
    T_CONTAINS(e.msg, "does not exist (expected 0..");
    char want[64];
    snprintf(want, sizeof want, "game stage %d does not exist (expected 0..%d)", G_STAGES, G_STAGES - 1);
    T_CONTAINS(e.msg, want);
    T_ASSERT(!r_stage_for_game(&st, -1, &e));
    T_EQ(e.code, R_STAGE_ERR_GAME);

    /* a data directory whose harbour file dresses the wrong stage, and no dojo file */
    const char *d = t_tmpdir();
    char dir[512];
    snprintf(dir, sizeof dir, "%s/shaders", d);
    T_EQ(mkdir(dir, 0755), 0);
    t_write(d, "stages/harbor.stage", "name = harbor\ngame = dojo\n");
    setenv("RINGSIDE_DATA", d, 1);
    rs_data_reset();
    T_ASSERT(!r_stage_for_game(&st, 1, &e));
    T_EQ(e.code, R_STAGE_ERR_GAME);
    T_CONTAINS(e.msg, "stages/harbor.stage: game is 'dojo', but this file dresses game stage 'harbor'");
    T_ASSERT(!r_stage_for_game(&st, 0, &e));
    T_EQ(e.code, R_STAGE_ERR_FILE);
    T_CONTAINS(e.msg, "stages/dojo.stage: cannot open: ");
    /* no data directory at all */
    setenv("RINGSIDE_DATA", "/nonexistent/ringside", 1);
    rs_data_reset();
    T_ASSERT(!r_stage_for_game(&st, 0, &e));
    T_EQ(e.code, R_STAGE_ERR_FILE);
    T_CONTAINS(e.msg, "RINGSIDE_DATA=/nonexistent/ringside");
}

static void t_load(void)
{
    const char *d = t_tmpdir();
    char p[512];
    r_stage st;
    rs_err e = {0};
    snprintf(p, sizeof p, "%s/missing.stage", d);
    T_ASSERT(!r_stage_load(&st, p, &e));
    T_EQ(e.code, R_STAGE_ERR_FILE);
    T_CONTAINS(e.msg, "missing.stage: cannot open: No such file or directory");

    t_write(d, "sub/ok.stage", "name = ok\ngame = temple\nenvironment = sky.hdr\n");
    snprintf(p, sizeof p, "%s/sub/ok.stage", d);
    T_ASSERTF(r_stage_load(&st, p, &e), "%s", e.msg);
    char want[600];
    snprintf(want, sizeof want, "%s/sub/sky.hdr", d);
    T_ASSERT(!strcmp(st.env_path, want)); /* existence is not checked */

    t_write(d, "bad.stage", "name = ok\ngame = temple\n\ngamma = 0\n");
    snprintf(p, sizeof p, "%s/bad.stage", d);
    T_ASSERT(!r_stage_load(&st, p, &e));
    T_EQ(e.code, R_STAGE_ERR_RANGE);
    snprintf(want, sizeof want, "%s:4: gamma: expected a number in 0.1..10, got '0'", p);
    T_CONTAINS(e.msg, want);

    char *big = malloc(R_STAGE_MAX_BYTES + 2);
    memset(big, '#', R_STAGE_MAX_BYTES + 1);
    big[R_STAGE_MAX_BYTES + 1] = 0;
    t_write(d, "big.stage", big);
    free(big);
    snprintf(p, sizeof p, "%s/big.stage", d);
    T_ASSERT(!r_stage_load(&st, p, &e));
    T_EQ(e.code, R_STAGE_ERR_FILE);
    T_CONTAINS(e.msg, "big.stage: larger than the limit of 65536 bytes");
}

/* Every id has a text, and no two share one. */
static void t_error_ids_have_texts(void)
{
    T_EQ(RS_ERR_MODULE(R_STAGE_ERR_BASE + 1), RS_ERR_MOD_R_STAGE);
    T_EQ(RS_ERR_MODULE(R_STAGE_ERR_END - 1), RS_ERR_MOD_R_STAGE);
    T_ASSERT(!strcmp(rs_err_module_name(R_STAGE_ERR_RANGE), "stage"));
    for (int a = R_STAGE_ERR_BASE + 1; a < R_STAGE_ERR_END; a++) {
        const char *t = r_stage_error_text(a);
        T_ASSERTF(t[0] && strcmp(t, "?") && strcmp(t, "ok"), "id %d has no text", a);
        for (int b = R_STAGE_ERR_BASE + 1; b < a; b++)
            T_ASSERTF(strcmp(t, r_stage_error_text(b)), "ids %d and %d share the text \"%s\"", b, a, t);
    }
    T_ASSERT(!strcmp(r_stage_error_text(R_STAGE_ERR_END), "?"));
}

T_MAIN({"error_ids_have_texts", t_error_ids_have_texts}, {"defaults", t_defaults}, {"every_key", t_every_key}, {"layout", t_layout},
       {"syntax_errors", t_syntax_errors}, {"missing_required", t_missing_required},
       {"value_errors", t_value_errors}, {"bounds", t_bounds}, {"directions_normalised", t_directions_normalised},
       {"environment_path", t_environment_path}, {"round_trip", t_round_trip},
       {"format_snprintf_rules", t_format_snprintf_rules}, {"randomized", t_randomized},
       {"shipped_stages", t_shipped_stages}, {"for_game", t_for_game}, {"load", t_load})
