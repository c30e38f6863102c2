/* test.h -- a minimal test harness. Each TEST registers itself at start-up;
 * tests/unit/test_main.c runs them (optionally filtered by a name substring)
 * and prints the plain closing line "N passed, N failed". A CHECK that fails
 * ends the current test and reports file, line and the failed condition. */
#ifndef SL_TEST_H
#define SL_TEST_H
#include <math.h>
#include <stdio.h>

typedef void (*TestFn)(void);
void test_register(const char *name, TestFn fn);
void test_fail(const char *file, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* Path of a fresh scratch directory for the current test (removed afterwards). */
const char *test_tmpdir(void);

#define TEST(name)                                                                   \
    static void name(void);                                                          \
    __attribute__((constructor)) static void name##_register(void) { test_register(#name, name); } \
    static void name(void)

#define CHECK(cond)                                               \
    do {                                                          \
        if (!(cond)) { test_fail(__FILE__, __LINE__, "%s", #cond); return; } \
    } while (0)

#define CHECK_MSG(cond, ...)                                      \
    do {                                                          \
        if (!(cond)) { test_fail(__FILE__, __LINE__, __VA_ARGS__); return; } \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                        \
    do {                                                                             \
        double a_ = (a), b_ = (b), t_ = (tol);                                       \
        if (!(fabs(a_ - b_) <= t_)) {                                                \
            test_fail(__FILE__, __LINE__, "%s = %.9g, %s = %.9g, |diff| > %.3g", #a, a_, #b, b_, t_); \
            return;                                                                  \
        }                                                                            \
    } while (0)

#endif
