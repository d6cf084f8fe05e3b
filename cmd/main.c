/* ringside: one binary, one subcommand per job.  Commands live in
 * cmd_*.c; each parses its own options, prints its own --help and returns
 * an exit status (0 ok, 1 failure, 2 usage).  Only this layer exits. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "../runtime/platform/plat.h"
#include "../runtime/util/rs_version.h"

static const cli_cmd commands[] = {
    {"info", cmd_info, "print the GL backend, driver and capabilities"},
    {"smoke", cmd_smoke, "render the smoke test scene headless to an image"},
    {"shaders", cmd_shaders, "compile every shader in shaders/ and report errors"},
    {"play", cmd_play, "play in a window (or watch a replay), fixed 60 Hz"},
    {"render", cmd_render, "render a replay to a video (.y4m, .mp4, ...), headless"},
    {"join", cmd_join, "join segments (render --segment) into one video, by stream copy"},
    {"record", cmd_record, "record a CPU-vs-CPU match headless to a replay"},
    {"attract", cmd_attract, "the cabinet's attract loop: movies and demos until a button starts a match"},
    {"movie", cmd_movie, "play a movie (Y4M or anything FFmpeg decodes) on the 60 Hz tick"},
    {"replay", cmd_replay, "a replay file: replay info, verify, sound (its track as a WAV), events"},
    {"serve", cmd_serve, "the replay-to-video daemon: HTTP API, dashboard, queue, workers"},
    {"bench", cmd_bench, "benchmarks: platform, sim, capture, accuracy, upload, encode, audio, quality"},
};

/* DESIGN: this text is also the source of ringside(1) (tools/man.sh) and of
 * the bash completion (tools/completion.sh): the usage block first, then
 * paragraphs, and lists as "  TERM  text" lines. */
static void usage(FILE *f)
{
    fprintf(f, "usage: ringside COMMAND [OPTIONS]\n"
               "       ringside help COMMAND\n\n"
               "ringside %s: arcade fighting-game runtime with replay capture.\n\n"
               "commands:\n",
            RS_VERSION);
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(f, "  %-9s %s\n", commands[i].name, commands[i].summary);
    fprintf(f, "  %-9s %s\n", "help", "this text; 'ringside COMMAND --help' for one command");
    fprintf(f, "  %-9s %s\n", "version", "print the version");
    fprintf(f, "\noptions every command takes, anywhere before --:\n"
               "  -q, --quiet            warnings and errors only (--loglevel warning)\n"
               "  -v, --verbose          everything (--loglevel debug): the GL driver, start-up\n"
               "                         times, the encoder's own log\n"
               "  --loglevel LEVEL       quiet (nothing: the exit status alone), error, warning,\n"
               "                         info (the default: what was done, progress) or debug\n");
    fprintf(f, "\nGL backends built in: %s (headless default: egl, then osmesa)\n"
               "\nenvironment:\n"
               "  RINGSIDE_DATA          the directory holding shaders/ and stages/ (default: found\n"
               "                         beside the binary in the source tree or the install prefix)\n"
               "  RINGSIDE_CACHE         where prefiltered lighting is cached (default:\n"
               "                         $XDG_CACHE_HOME/ringside or ~/.cache/ringside; off: no cache)\n"
               "  RINGSIDE_GL_DEBUG=1    GL debug messages on stderr\n"
               "  RINGSIDE_EGL_DEVICE=N  the EGL device to use (default: the first that works)\n"
               "  RINGSIDE_OIIO_PLUGIN   OpenImageIO's plugin, loaded for image files (default:\n"
               "                         ringside-oiio.so beside the binary or in ../lib/ringside)\n"
               "  RS_PROGRESS_INTERVAL   seconds between --progress plain lines (default 5)\n"
               "  TMPDIR                 where render - keeps the replay for --jobs (default /tmp)\n"
               "\nfiles:\n"
               "  ~/.cache/ringside      the prefiltered lighting of each stage (RINGSIDE_CACHE)\n"
               "  share/ringside         shaders/ and stages/ of an installed ringside\n"
               "  share/doc/ringside     README.md, docs/ and ringside.conf.example\n"
               "\nexamples:\n"
               "  ringside render demos/dojo.rsr -o dojo.mp4\n"
               "                         a replay to a video: 640x360, 60 fps, sound, the default quality\n"
               "  ringside record --ai --seconds 30 -o m.rsr\n"
               "                         a CPU-vs-CPU match to a replay file\n"
               "  ringside replay verify m.rsr\n"
               "                         re-simulate a replay and check its state hashes\n"
               "  ringside serve --config /etc/ringside.conf\n"
               "                         the replay-to-video daemon and its dashboard\n"
               "\nexit status:\n"
               "  0  success\n"
               "  1  failure: the message names the file and the reason\n"
               "  2  bad usage: an option, a value or an output name that cannot work\n"
               "  3  join: one or more segments are bad (named, to be rendered again)\n"
               "  4  render -o -: the program reading the stream closed it early\n"
               "\ndocs: 'man ringside-COMMAND'; README.md and docs/ (installed in share/doc/ringside)\n",
            plat_built_backends());
}

int main(int argc, char **argv)
{
    if (!cli_log_options(&argc, argv))
        return RS_EXIT_USAGE;
    if (argc < 2) {
        usage(stderr);
        return RS_EXIT_USAGE;
    }
    const char *name = argv[1];
    if (!strcmp(name, "help") || !strcmp(name, "--help") || !strcmp(name, "-h")) {
        if (argc > 2 && strcmp(name, "help") == 0) {
            for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
                if (!strcmp(commands[i].name, argv[2])) {
                    char *args[] = {argv[2], "--help", NULL};
                    return commands[i].run(2, args);
                }
        }
        usage(stdout);
        return RS_EXIT_OK;
    }
    if (!strcmp(name, "version") || !strcmp(name, "--version")) {
        printf("ringside %s\n", RS_VERSION);
        return RS_EXIT_OK;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (!strcmp(commands[i].name, name)) {
            cli_command = name;
            return commands[i].run(argc - 1, argv + 1);
        }
    if (rs_log_on(RS_LOG_ERROR))
        fprintf(stderr, "ringside: unknown command '%s' (see 'ringside --help')\n", name);
    return RS_EXIT_USAGE;
}
