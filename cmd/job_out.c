#include "job_out.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../capture/cap_seg.h"
#include "cli.h"
#include "job_err.h"

bool job_out_check(job_out *o)
{
    bool ow = o->overwrite;
    if (o->audio)
        o->audio->overwrite = ow;
    return (o->pattern ? cli_pattern_ok(o->cmd, o->video, o->first, o->end, ow) : cli_out_ok(o->cmd, o->video, ow)) &&
           (!o->hashes || !strcmp(o->hashes, "-") || cli_out_ok(o->cmd, o->hashes, ow)) &&
           (!o->manifest || cli_out_ok(o->cmd, o->manifest, ow)) &&
           (!o->poster || !o->poster->due || cli_out_ok(o->cmd, o->poster->path, ow));
}

bool job_out_open(job_out *o, rs_err *err)
{
    if (o->manifest && unlink(o->manifest) != 0 && errno != ENOENT)
        return rs_fail(err, JOB_ERR_WRITE, "%s: cannot remove the old manifest: %s", o->manifest, strerror(errno));
    if (o->hashes && !strcmp(o->hashes, "-")) {
        o->hash_file = stdout;
    } else if (o->hashes) {
        snprintf(o->hpart, sizeof o->hpart, "%s.part", o->hashes);
        if (!(o->hf = fopen(o->hpart, "w")))
            return rs_fail(err, JOB_ERR_CREATE, "%s: cannot create (as %s): %s", o->hashes, o->hpart, strerror(errno));
        o->hash_file = o->hf;
    }
    return true;
}

/* The video is in place; an output that goes with it failed. */
static void remove_video(const job_out *o)
{
    struct stat vst;
    if (stat(o->video, &vst) == 0 && S_ISREG(vst.st_mode))
        unlink(o->video);
}

/* The manifest, last: without it, no segment, so the files go too. */
static bool seal(job_out *o, rs_err *err)
{
    uint64_t replay_fnv = 0; /* join --replay checks it is the segments' */
    if (cap_seg_replay_fnv(o->replay, &replay_fnv, err) &&
        cap_seg_seal(o->video, o->key, o->first, o->end, o->hashes, &replay_fnv, err))
        return true;
    unlink(o->video);
    if (o->hashes)
        unlink(o->hashes);
    if (o->poster && o->poster->due)
        unlink(o->poster->path);
    if (o->audio && o->audio->wav)
        unlink(o->audio->wav);
    return false;
}

bool job_out_commit(job_out *o, rs_err *err)
{
    if (o->hash_file == stdout && fflush(stdout) != 0)
        return rs_fail(err, JOB_ERR_WRITE, "--hashes -: write failed");
    if (o->hf) {
        bool hok = fclose(o->hf) == 0;
        o->hf = NULL;
        if (!hok || rename(o->hpart, o->hashes) != 0) {
            /* the video and its hash list go together: without the list, no video */
            remove_video(o);
            return rs_fail(err, JOB_ERR_WRITE, "%s: write failed; %s removed with it", o->hashes, o->video);
        }
        o->hpart[0] = 0;
    }
    if (o->audio && !job_audio_commit(o->audio, err)) {
        remove_video(o); /* the video and its WAV go together, as with the hash list */
        return false;
    }
    if (o->poster && !job_poster_commit(o->poster, err))
        return false;
    return !o->manifest || seal(o, err);
}

void job_out_abandon(job_out *o)
{
    if (o->hf)
        fclose(o->hf);
    o->hf = NULL;
    if (o->hpart[0])
        unlink(o->hpart);
    o->hpart[0] = 0;
    if (o->poster)
        job_poster_abandon(o->poster);
}
