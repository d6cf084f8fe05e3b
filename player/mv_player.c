/* One movie on the 60 Hz tick: source, decode thread, upload, pacing
 * (mv_player.h). */
#include "mv_player.h"

#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "mv_dec.h"

struct mv_player {
    mv_src *src;
    mv_dec *dec;
    mv_up *up;
    mv_audio *audio;    /* NULL: silent (audio_err says why) */
    rs_err audio_err;
    int nslots;
    int64_t tick;       /* the next tick to play */
    int64_t shown;      /* frame on the textures */
    int64_t staged;     /* PBO: frame waiting in the staged buffer, -1 none */
    bool wait;
    bool pending[MV_DEC_MAX_SLOTS]; /* PERSISTENT: held until the GPU is done */
    bool over;
    mv_stats st;
};

int64_t mv_frame_for_tick(int64_t tick, int fps_num, int fps_den)
{
    /* floor(t * num / (60 * den)): the frame whose display interval holds the tick */
    if (tick < 0 || fps_num <= 0 || fps_den <= 0)
        return 0;
    __int128 n = (__int128)tick * fps_num;
    return (int64_t)(n / ((__int128)60 * fps_den));
}

mv_player *mv_player_open(const char *path, const mv_player_opts *o, rs_err *err)
{
    mv_player_opts def = {0};
    if (!o)
        o = &def;
    mv_player *p = calloc(1, sizeof *p);
    if (!p) {
        rs_fail(err, MV_ERR_NOMEM, "%s: out of memory", path);
        return NULL;
    }
    p->shown = p->staged = -1;
    p->wait = o->wait;
    p->nslots = o->slots > 0 ? o->slots : 4;
    if (p->nslots > MV_DEC_MAX_SLOTS)
        p->nslots = MV_DEC_MAX_SLOTS;
    if (!(p->src = mv_open(path, err)))
        goto fail;
    mv_info *i = &p->src->info;
    if (o->matrix) {
        i->matrix = o->matrix == MV_OVERRIDE_709 ? MV_BT709 : MV_BT601;
        i->matrix_guessed = false;
    }
    if (o->range)
        i->full_range = o->range == MV_OVERRIDE_FULL;
    if (!(p->up = mv_up_create(i, o->upload, p->nslots, err))) {
        rs_err_prefix(err, "%s", path);
        goto fail;
    }
    uint8_t *slots[MV_DEC_MAX_SLOTS];
    for (int k = 0; k < p->nslots; k++)
        slots[k] = mv_up_slot(p->up, k);
    if (!(p->dec = mv_dec_start(p->src, slots, p->nslots, err))) {
        rs_err_prefix(err, "%s", path);
        goto fail;
    }
    /* Y4M has no sound; anything else may.  A soundtrack that cannot be
     * played leaves the movie silent, never unplayable. */
    if (!o->mute && strcmp(i->codec, "y4m") && (p->audio = mv_audio_open(path, &p->audio_err)))
        mv_audio_prime(p->audio, AU_TICK_FRAMES, 250); /* the first tick on time; a load-time wait */
    return p;
fail:
    mv_player_close(p);
    return NULL;
}

const mv_info *mv_player_info(const mv_player *p)
{
    return &p->src->info;
}

int mv_player_upload(const mv_player *p)
{
    return mv_up_mode(p->up);
}

/* PERSISTENT: give back slots the GPU has finished reading. */
static void reclaim(mv_player *p, bool wait)
{
    for (int k = 0; k < p->nslots; k++)
        if (p->pending[k] && !mv_up_busy(p->up, k, wait)) {
            p->pending[k] = false;
            mv_dec_release(p->dec, k);
        }
}

static void done_with(mv_player *p, int slot)
{
    if (mv_up_mode(p->up) == MV_UP_PERSISTENT)
        p->pending[slot] = true;
    else
        mv_dec_release(p->dec, slot);
}

/* The frame `want` at the head of the queue: drops older frames.
 * MV_DEC_FRAME with *slot popped and held; or NONE / END / ERROR. */
static int take(mv_player *p, int64_t want, bool wait, int *slot)
{
    for (;;) {
        int64_t index;
        int r = mv_dec_peek(p->dec, 0, slot, &index);
        if (r == MV_DEC_NONE && wait) {
            /* In PERSISTENT mode the decoder may be out of slots because
             * the GPU still reads them: reclaim before sleeping. */
            reclaim(p, true);
            r = mv_dec_peek(p->dec, 50, slot, &index);
            if (r == MV_DEC_NONE)
                continue;
        }
        if (r != MV_DEC_FRAME)
            return r;
        if (index > want)
            return MV_DEC_NONE; /* cannot happen: frames come in order */
        mv_dec_pop(p->dec);
        if (index == want)
            return MV_DEC_FRAME;
        p->st.dropped++;
        mv_dec_release(p->dec, *slot);
    }
}

int mv_player_tick(mv_player *p, rs_err *err)
{
    if (p->over)
        return 0;
    const mv_info *i = &p->src->info;
    reclaim(p, false);
    int64_t want = mv_frame_for_tick(p->tick, i->fps_num, i->fps_den);
    if (want != p->shown) {
        if (p->staged == want) {
            mv_up_commit(p->up);
            p->shown = want;
            p->st.shown++;
        } else {
            int slot, r = take(p, want, p->wait, &slot);
            if (r == MV_DEC_FRAME) {
                mv_up_upload(p->up, slot);
                done_with(p, slot);
                p->shown = want;
                p->st.shown++;
                if (mv_up_mode(p->up) == MV_UP_PBO)
                    p->st.unstaged++;
            } else if (r == MV_DEC_END) {
                p->over = true;
                return 0;
            } else if (r == MV_DEC_ERROR) {
                p->over = true;
                *err = *mv_dec_error(p->dec);
                return -1;
            } else {
                p->st.late++;
            }
            p->staged = -1;
        }
    } else {
        p->st.repeats++;
    }
    /* PBO ping-pong: copy the next tick's frame now, while the textures are
     * defined from the other buffer. */
    if (mv_up_mode(p->up) == MV_UP_PBO && p->shown >= 0) {
        int64_t next = mv_frame_for_tick(p->tick + 1, i->fps_num, i->fps_den);
        if (next != p->shown && p->staged != next) {
            int slot;
            if (take(p, next, p->wait, &slot) == MV_DEC_FRAME) {
                if (mv_up_stage(p->up, slot))
                    p->staged = next;
                mv_dec_release(p->dec, slot);
            }
        }
    }
    p->tick++;
    p->st.ticks++;
    return 1; /* shown < 0 (a late first frame): mv_player_draw clears to black */
}

int64_t mv_player_frame(const mv_player *p)
{
    return p->shown;
}

bool mv_player_audio(mv_player *p, float *out, int frames)
{
    if (!p->audio || p->tick == 0) {
        memset(out, 0, (size_t)frames * 2 * sizeof *out);
        return true;
    }
    return mv_audio_read(p->audio, (p->tick - 1) * AU_TICK_FRAMES, out, frames, p->wait);
}

const mv_audio_info *mv_player_audio_info(const mv_player *p)
{
    return p->audio ? mv_audio_info_get(p->audio) : NULL;
}

const char *mv_player_audio_why(const mv_player *p)
{
    return p->audio_err.msg;
}

void mv_player_draw(mv_player *p, int vw, int vh)
{
    if (p->shown < 0) {
        gl.Viewport(0, 0, vw, vh);
        gl.ClearColor(0, 0, 0, 1);
        gl.Clear(GL_COLOR_BUFFER_BIT);
        return;
    }
    mv_up_draw(p->up, vw, vh);
}

void mv_player_stats(const mv_player *p, mv_stats *st)
{
    *st = p->st;
    if (p->dec)
        mv_dec_stats(p->dec, &st->decode_ms, &st->decoded);
    if (p->up)
        mv_up_stats_get(p->up, &st->up);
    if (p->audio)
        mv_audio_stats_get(p->audio, &st->audio);
}

void mv_player_close(mv_player *p)
{
    if (!p)
        return;
    mv_audio_close(p->audio);
    mv_dec_stop(p->dec); /* before the slot memory goes */
    mv_up_destroy(p->up);
    mv_close(p->src);
    free(p);
}
