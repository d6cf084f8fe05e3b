/* mv_player: one movie on the 60 Hz tick.
 *
 * Pacing: tick t shows the frame on screen at the tick's time, the latest
 * whose presentation time has come: frame = floor(t * fps / 60).  60 fps is
 * 1:1, 30 fps shows each frame for 2 ticks, 24 fps alternates 3 and 2 ticks
 * (2:3 pulldown), 25 fps gives 3,2,3,2,2 ...; rates above 60 skip frames.
 * No frame is ever shown before its time, and a movie of N frames lasts
 * exactly ceil(N * 60 / fps) ticks.
 *
 * Each tick (mv_player_tick) the player makes the textures hold that frame.
 * In PBO mode it also copies the *next* tick's frame into the idle buffer
 * (the ping-pong), so the textures are defined from a buffer
 * filled a tick earlier.  A frame the decoder has not delivered in time is
 * counted late and the previous frame stays on screen; in `wait` mode
 * (headless, exact output) the player waits for it instead. */
#ifndef MV_PLAYER_H
#define MV_PLAYER_H

#include <stdbool.h>
#include <stdint.h>

#include "mv.h"
#include "mv_audio.h"
#include "mv_up.h"

enum { MV_OVERRIDE_601 = 1, MV_OVERRIDE_709, MV_OVERRIDE_LIMITED = 1, MV_OVERRIDE_FULL };

typedef struct mv_player_opts {
    int upload;     /* MV_UP_*; default (0) PBO */
    bool wait;      /* wait for the decoder instead of repeating a frame */
    int matrix;     /* 0: the stream's; MV_OVERRIDE_601 / _709 */
    int range;      /* 0: the stream's; MV_OVERRIDE_LIMITED / _FULL */
    int slots;      /* decode queue depth; 0 -> 4 */
    bool mute;      /* do not decode the soundtrack (mv_player_audio gives silence) */
} mv_player_opts;

typedef struct mv_stats {
    int64_t ticks;    /* ticks played */
    int64_t shown;    /* distinct frames put on the textures */
    int64_t repeats;  /* ticks that kept the previous frame because of the cadence */
    int64_t late;     /* ticks whose frame was not decoded in time (previous frame kept) */
    int64_t dropped;  /* decoded frames never shown (rate above 60, or catching up) */
    int64_t unstaged; /* PBO: frames defined without a tick of look-ahead */
    int64_t decoded;
    double decode_ms; /* decoder thread time */
    mv_up_stats up;
    mv_audio_stats audio; /* zero without a soundtrack */
} mv_stats;

typedef struct mv_player mv_player;

/* floor(t * num / (60 * den)); exact integer arithmetic. */
int64_t mv_frame_for_tick(int64_t tick, int fps_num, int fps_den);

/* Opens the movie, creates its textures (GL context current) and starts
 * the decoder.  NULL with err naming the file on failure. */
mv_player *mv_player_open(const char *path, const mv_player_opts *o, rs_err *err);
const mv_info *mv_player_info(const mv_player *p);
int mv_player_upload(const mv_player *p); /* MV_UP_* */

/* Advances one tick: 1 the tick's frame (or the last one, when late) is on
 * the textures; 0 the movie is over (nothing changed); -1 the decoder
 * failed (err says why, with the path and frame). */
int mv_player_tick(mv_player *p, rs_err *err);
/* The frame index on the textures, -1 before the first. */
int64_t mv_player_frame(const mv_player *p);
/* The soundtrack of the tick just played (mv_audio.h: tick t is frames
 * [t * AU_TICK_FRAMES, t * AU_TICK_FRAMES + frames) of the track), frames
 * stereo 48 kHz float frames into out.  Silence before the first tick,
 * after the track's end, and for a movie without sound.  Not decoded in
 * time: silence, counted late, false; in `wait` mode it waits instead. */
bool mv_player_audio(mv_player *p, float *out, int frames);
/* The soundtrack's stream, or NULL when the movie plays silent; then
 * mv_player_audio_why says why ("" for a movie with no audio stream,
 * else the message: an undecodable codec, ...). */
const mv_audio_info *mv_player_audio_info(const mv_player *p);
const char *mv_player_audio_why(const mv_player *p);
void mv_player_draw(mv_player *p, int vw, int vh);
void mv_player_stats(const mv_player *p, mv_stats *st);
void mv_player_close(mv_player *p);

#endif
