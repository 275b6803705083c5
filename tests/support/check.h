/*
 * check.h -- the tiny assertion harness of getme's C tests.
 *
 *   CHECK(cond)                 fails the test (and goes on) if cond is false
 *   CHECK_NEAR(a, b, tol)       |a - b| <= tol
 *   CHECK_EQ_INT(a, b)          integers equal
 *   return check_summary("name");  prints "name: N passed, M failed" and
 *                                  returns the exit status (0 iff no failure)
 *
 * Every failure prints file:line and the values, so a red test says why.
 */
#ifndef GETME_TEST_CHECK_H
#define GETME_TEST_CHECK_H

#include <math.h>
#include <stdio.h>

static int check_passed_ = 0, check_failed_ = 0;

#define CHECK(cond)                                                         \
    do {                                                                    \
        if (cond) {                                                         \
            check_passed_++;                                                \
        } else {                                                            \
            check_failed_++;                                                \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, \
                    #cond);                                                 \
        }                                                                   \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                               \
    do {                                                                    \
        double check_a_ = (a), check_b_ = (b);                              \
        if (fabs(check_a_ - check_b_) <= (tol)) {                           \
            check_passed_++;                                                \
        } else {                                                            \
            check_failed_++;                                                \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.17g, %s = %.17g (tol %g)\n", \
                    __FILE__, __LINE__, #a, check_a_, #b, check_b_,        \
                    (double)(tol));                                         \
        }                                                                   \
    } while (0)

#define CHECK_EQ_INT(a, b)                                                  \
    do {                                                                    \
        long long check_a_ = (long long)(a), check_b_ = (long long)(b);     \
        if (check_a_ == check_b_) {                                         \
            check_passed_++;                                                \
        } else {                                                            \
            check_failed_++;                                                \
            fprintf(stderr, "%s:%d: CHECK_EQ_INT failed: %s = %lld, %s = %lld\n", \
                    __FILE__, __LINE__, #a, check_a_, #b, check_b_);        \
        }                                                                   \
    } while (0)

static inline int check_summary(const char *name)
{
    printf("%s: %d passed, %d failed\n", name, check_passed_, check_failed_);
    return check_failed_ == 0 && check_passed_ > 0 ? 0 : 1;
}

#endif /* GETME_TEST_CHECK_H */
