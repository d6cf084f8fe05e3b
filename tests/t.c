#define _GNU_SOURCE /* mkdtemp, setenv */
#include "t.h"

#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "../runtime/platform/plat.h"

#ifdef RS_SANITIZE
#include <sanitizer/lsan_interface.h>
#endif

#define T_SKIP_CODE 77         /* environment (tests/lib.sh: the same codes) */
#define T_SKIP_INSTALL_CODE 78 /* missing install */
#define T_TIMEOUT_S 300

static bool nofork;
static jmp_buf jump;
static int jump_code;
static char tmpdir[256];

_Noreturn void t_fail(const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "    %s:%d: ", file, line);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    fflush(stderr);
    if (nofork) {
        jump_code = 1;
        longjmp(jump, 1);
    }
    _exit(1);
}

/* The reason goes to stderr and to a file in the case's directory, where
 * the runner reads it for the verdict line. */
_Noreturn void t_skip(int install, const char *fmt, ...)
{
    char why[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    const char *kind = install ? "missing install" : "environment";
    fprintf(stderr, "    skip (%s): %s\n", kind, why);
    fflush(stderr);
    char path[300];
    snprintf(path, sizeof path, "%s/.t-skip", t_tmpdir());
    FILE *f = fopen(path, "w");
    if (f) {
        fprintf(f, "%s: %s", kind, why);
        fclose(f);
    }
    int code = install ? T_SKIP_INSTALL_CODE : T_SKIP_CODE;
    if (nofork) {
        jump_code = code;
        longjmp(jump, 1);
    }
    _exit(code);
}

/* The reason a case skipped, from its directory ("KIND: WHY"). */
static void skip_reason(char *out, size_t n)
{
    char path[300];
    snprintf(path, sizeof path, "%s/.t-skip", tmpdir);
    snprintf(out, n, "no reason given");
    FILE *f = tmpdir[0] ? fopen(path, "r") : NULL;
    if (!f)
        return;
    if (!fgets(out, (int)n, f))
        snprintf(out, n, "no reason given");
    fclose(f);
    out[strcspn(out, "\n")] = 0;
}

const char *t_tmpdir(void)
{
    if (!tmpdir[0]) {
        const char *base = getenv("TMPDIR");
        snprintf(tmpdir, sizeof tmpdir, "%s/ringside-test-XXXXXX", base && *base ? base : "/tmp");
        if (!mkdtemp(tmpdir))
            t_fail(__FILE__, __LINE__, "mkdtemp %s: %s", tmpdir, strerror(errno));
    }
    return tmpdir;
}

void t_write(const char *dir, const char *name, const char *text)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    for (char *s = path + strlen(dir) + 1; (s = strchr(s, '/')) != NULL; s++) {
        *s = 0;
        mkdir(path, 0755);
        *s = '/';
    }
    FILE *f = fopen(path, "w");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0)
        t_fail(__FILE__, __LINE__, "cannot write %s", path);
}

struct plat *t_context(const char *backend)
{
    if (!plat_backend_built(backend))
        t_skip(1, "backend %s not built in (built: %s)", backend, plat_built_backends());
    rs_err err = {0};
    plat *p = plat_create(&(plat_desc){.backend = backend, .hidden = true, .debug = true}, &err);
    if (!p)
        t_fail(__FILE__, __LINE__, "%s context: %s", backend, err.msg);
    return p;
}

static void rm_tree(const char *dir)
{
    if (!dir[0])
        return;
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "    warning: could not remove %s\n", dir);
}

/* setjmp lives here so t_main's locals are not clobbered by longjmp */
static int run_inline(void (*fn)(void))
{
    jump_code = 0;
    if (setjmp(jump) == 0)
        fn();
    return jump_code;
}

/* An argument selects the cases whose names contain it, or with a leading
 * '=' the case of exactly that name (tests/run.sh's tiers use these). */
static bool selected(const char *name, int argc, char **argv)
{
    if (argc < 2)
        return true;
    for (int i = 1; i < argc; i++)
        if (argv[i][0] == '=' ? !strcmp(name, argv[i] + 1) : strstr(name, argv[i]) != NULL)
            return true;
    return false;
}

int t_main(int argc, char **argv, const t_case *cases, size_t n)
{
    const char *suite = strrchr(argv[0], '/');
    suite = suite ? suite + 1 : argv[0];
#ifdef RS_SOURCE_DIR
    setenv("RINGSIDE_DATA", RS_SOURCE_DIR, 0);
#endif
    nofork = getenv("T_NOFORK") && *getenv("T_NOFORK") == '1';
    if (nofork) {
        /* in-process cases share environment and cwd: allow exactly one */
        size_t sel = 0;
        for (size_t i = 0; i < n; i++)
            sel += selected(cases[i].name, argc, argv);
        if (sel != 1) {
            fprintf(stderr, "T_NOFORK=1 runs one case in-process (for a debugger); %zu match, name one\n", sel);
            printf("0 passed, 1 failed, 0 skipped\n");
            return 1;
        }
    }
    int pass = 0, fail = 0, skip = 0;
    bool ci = getenv("CI") && !strcmp(getenv("CI"), "true");
    for (size_t i = 0; i < n; i++) {
        if (!selected(cases[i].name, argc, argv))
            continue;
        fflush(stdout);
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        int code;
        const char *why = "";
        char whybuf[64], skipbuf[420] = "";
        if (nofork) {
            code = run_inline(cases[i].fn);
            if (code == T_SKIP_CODE || code == T_SKIP_INSTALL_CODE)
                skip_reason(skipbuf, sizeof skipbuf);
            rm_tree(tmpdir);
            tmpdir[0] = 0;
        } else {
            /* the directory is made by the parent so it can clean up after a crash */
            t_tmpdir();
            pid_t pid = fork();
            if (pid == 0) {
                alarm(T_TIMEOUT_S);
                cases[i].fn();
                fflush(stdout);
                /* a case may have lowered the file size limit (disk-full
                 * tests): LeakSanitizer's tracer deadlocks under it */
                struct rlimit rl;
                if (getrlimit(RLIMIT_FSIZE, &rl) == 0) {
                    rl.rlim_cur = rl.rlim_max;
                    setrlimit(RLIMIT_FSIZE, &rl);
                }
                signal(SIGXFSZ, SIG_DFL);
#ifdef RS_SANITIZE
                /* _exit skips LeakSanitizer's exit-time check: run it here */
                if (__lsan_do_recoverable_leak_check())
                    _exit(1);
#endif
                _exit(0);
            }
            int st = 0;
            while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
            }
            if (WIFEXITED(st)) {
                code = WEXITSTATUS(st);
            } else {
                code = 1;
                snprintf(whybuf, sizeof whybuf, " (%s %d)",
                         WTERMSIG(st) == SIGALRM ? "timed out after" : "killed by signal",
                         WTERMSIG(st) == SIGALRM ? T_TIMEOUT_S : WTERMSIG(st));
                why = whybuf;
            }
            if (code == T_SKIP_CODE || code == T_SKIP_INSTALL_CODE)
                skip_reason(skipbuf, sizeof skipbuf);
            rm_tree(tmpdir);
            tmpdir[0] = 0;
        }
        /* each verdict line ends with the case's wall time: tests/run.sh
         * sums them into the slowest-cases table */
        clock_gettime(CLOCK_MONOTONIC, &t1);
        double secs = (double)(t1.tv_sec - t0.tv_sec) + (double)(t1.tv_nsec - t0.tv_nsec) / 1e9;
        if (code == 0) {
            pass++;
            printf("ok   %s/%s (%.2f s)\n", suite, cases[i].name, secs);
        } else if (code == T_SKIP_INSTALL_CODE && ci) {
            /* a CI machine must have everything tools/deps.sh installs */
            fail++;
            printf("FAIL %s/%s (CI=true, and a %s) (%.2f s)\n", suite, cases[i].name, skipbuf, secs);
        } else if (code == T_SKIP_CODE || code == T_SKIP_INSTALL_CODE) {
            skip++;
            printf("skip %s/%s (%s) (%.2f s)\n", suite, cases[i].name, skipbuf, secs);
        } else {
            fail++;
            printf("FAIL %s/%s%s (%.2f s)\n", suite, cases[i].name, why, secs);
        }
        fflush(stdout);
    }
    printf("%d passed, %d failed, %d skipped\n", pass, fail, skip);
    return fail ? 1 : 0;
}
