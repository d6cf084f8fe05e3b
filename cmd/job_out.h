/* job_out: the outputs of a job (a render, a join), beside the video.
 *
 * A job declares what it writes before any work: the video (its sink
 * writes NAME.part and puts it in place in cap_close), the frame hash
 * list, the poster (job_poster), the WAV (job_audio) and a segment's
 * manifest.  job_out checks them all against -y/-n before anything is
 * touched, opens the hash list as NAME.part, and after the video is in
 * place puts the rest in place, or removes the video and everything else
 * the job wrote: the outputs appear together or not at all.
 *
 *   job_out o = {.cmd = "render", .video = out, .hashes = h, ...};
 *   if (!job_out_check(&o)) ...        said on stderr, naming the output
 *   if (!job_out_open(&o, err)) ...    old manifest gone; o.hash_file open
 *   ... the frames; cap_close(ok) puts the video in place ...
 *   if (!job_out_commit(&o, err)) ...  hashes, WAV, poster, manifest
 *   job_out_abandon(&o);               always: removes what a failure left
 *
 * Runs on the command's thread. */
#ifndef JOB_OUT_H
#define JOB_OUT_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "../runtime/util/rs_err.h"
#include "job_audio.h"
#include "job_poster.h"

typedef struct job_out {
    const char *cmd;       /* the command, for messages: "render" */
    bool overwrite;        /* -y: replace outputs that exist; else refuse them */
    const char *video;     /* the video ('-' and devices are streamed, never removed) */
    bool pattern;          /* video is an image pattern, frames first..end-1 */
    uint64_t first, end;
    const char *hashes;    /* the frame hash list: NULL, "-" (standard output) or a file */
    const char *manifest;  /* a segment's manifest (cap_seg_manifest_path), or NULL */
    const char *key;       /* the segment's key, written in the manifest */
    const char *replay;    /* the replay, named in the manifest by its FNV-1a */
    job_poster *poster;    /* NULL, or planned by job_poster_plan */
    job_audio *audio;      /* NULL, or its --wav goes with the video */
    FILE *hash_file;       /* after job_out_open: where frame hashes go (NULL: nowhere) */
    FILE *hf;              /* the hash list's NAME.part while it is written */
    char hpart[1100];
} job_out;

/* Every output the job writes, against -y/-n (cli_out_ok, cli_pattern_ok),
 * in the order video, hashes, manifest, poster; the WAV is job_audio_check's.
 * False after saying which output is refused. */
bool job_out_check(job_out *o);

/* Before the first frame: removes an old manifest (it must not vouch for
 * the files this job replaces) and opens the hash list as NAME.part. */
bool job_out_open(job_out *o, rs_err *err);

/* After cap_close put the video in place: the hash list, the WAV, the
 * poster, then the manifest, which says "complete".  On a failure the
 * video goes with the rest and err says what failed. */
bool job_out_commit(job_out *o, rs_err *err);

/* Removes the NAME.part files a failure left (the hash list, the poster). */
void job_out_abandon(job_out *o);

#endif
