/* The ringside test harness: one test file per module, one binary each.
 *
 *   static void t_something(void) { T_ASSERT(x == 1); }
 *   T_MAIN({"something", t_something}, ...)
 *
 * Each case runs in a forked child (a crash or a hang fails that case only;
 * T_NOFORK=1 runs in-process for gdb).  A binary runs alone:
 *   build/tests/test_shader [NAME-SUBSTRING... | =EXACT-NAME...]
 * and ends with "N passed, N failed, N skipped"; tests/run.sh sums them. */
#ifndef T_H
#define T_H

#include <stdbool.h>
#include <stddef.h>
#include <string.h>

typedef struct t_case {
    const char *name;
    void (*fn)(void);
} t_case;

int t_main(int argc, char **argv, const t_case *cases, size_t n);
_Noreturn void t_fail(const char *file, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* A case that cannot run here: install = 0 for the machine or the run (no
 * device, no server given, too busy to time), 1 for a tool or library
 * tools/deps.sh installs, which fails the case under CI=true
 * (docs/testing.md, "Skips"). */
_Noreturn void t_skip(int install, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#define T_MAIN(...)                                                                      \
    static const t_case t_cases_[] = {__VA_ARGS__};                                      \
    int main(int argc, char **argv)                                                      \
    {                                                                                    \
        return t_main(argc, argv, t_cases_, sizeof t_cases_ / sizeof t_cases_[0]);       \
    }

#define T_ASSERT(c)                                                                      \
    do {                                                                                 \
        if (!(c))                                                                        \
            t_fail(__FILE__, __LINE__, "%s", #c);                                        \
    } while (0)
#define T_ASSERTF(c, ...)                                                                \
    do {                                                                                 \
        if (!(c))                                                                        \
            t_fail(__FILE__, __LINE__, __VA_ARGS__);                                     \
    } while (0)
#define T_EQ(a, b)                                                                       \
    do {                                                                                 \
        long long t_a_ = (long long)(a), t_b_ = (long long)(b);                          \
        if (t_a_ != t_b_)                                                                \
            t_fail(__FILE__, __LINE__, "%s == %s: got %lld, want %lld", #a, #b, t_a_, t_b_); \
    } while (0)
#define T_CONTAINS(hay, needle)                                                          \
    do {                                                                                 \
        const char *t_h_ = (hay), *t_n_ = (needle);                                      \
        if (!t_h_ || !strstr(t_h_, t_n_))                                                \
            t_fail(__FILE__, __LINE__, "expected \"%s\" in \"%s\"", t_n_, t_h_ ? t_h_ : "(null)"); \
    } while (0)
#define T_SKIP_ENV(...) t_skip(0, __VA_ARGS__)
#define T_SKIP_INSTALL(...) t_skip(1, __VA_ARGS__)

/* A fresh directory for this case, removed by the runner afterwards. */
const char *t_tmpdir(void);
/* Writes text to dir/name (creating dir/name's parent); fails the test on error. */
void t_write(const char *dir, const char *name, const char *text);

/* A GL context on a headless backend, or a skip when it is not built in.
 * Destroyed when the case's process ends. */
struct plat;
struct plat *t_context(const char *backend);

#endif
