/*
 * test_digits.c -- the ASCII fast path's integer tokens eight digits at a
 * time (formats/msh/msh41_digits.h) against the digit-at-a-time loop it
 * replaced and against strtoull:
 *  - fixed cases: 1 to 26 digits, leading zeros, the 18/19-digit limit,
 *    the bytes next to '0'-'9' ('/', ':', and the same with the high bit
 *    set) right after or inside a token, no digit at all;
 *  - random tokens (lengths 0-26, random digits, leading zeros, any byte
 *    after them) at every distance from the end of the readable text, so
 *    both the eight-byte steps and the short-tail loop are taken.
 * The result, the value and the end pointer must be the loop's.
 */
#include "check.h"
#include "msh41_digits.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t rng = 0x9E3779B97F4A7C15u;
static uint32_t rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 11);
}

/* The token s (len bytes) at the start of a buffer whose readable text
   ends pad bytes after it; both parsers must agree. */
static int agree(const char *s, size_t len, size_t pad, int *rc_out,
                 uint64_t *v_out)
{
    char *buf = malloc(len + pad + 1);
    memcpy(buf, s, len);
    for (size_t i = 0; i < pad; i++)
        buf[len + i] = i == pad - 1 ? '\n' : (char)(rnd() & 0xff);
    buf[len + pad] = 0;
    const char *end = buf + len + pad;
    const char *a1 = NULL, *a2 = NULL;
    uint64_t v1 = 0, v2 = 0;
    int r1 = msh41_digits(buf, end, &a1, &v1);
    int r2 = msh41_digits_scalar(buf, &a2, &v2);
    int same = r1 == r2 && (r1 != 0 || (v1 == v2 && a1 == a2));
    *rc_out = r1;
    *v_out = v1;
    free(buf);
    return same;
}

static void fixed_case(const char *tok, int want_rc, uint64_t want_v)
{
    for (size_t pad = 1; pad <= 40; pad++) {
        char s[64];
        snprintf(s, sizeof s, "%s", tok);
        int rc;
        uint64_t v;
        int same = agree(s, strlen(s), pad, &rc, &v);
        CHECK(same);
        CHECK_EQ_INT(rc, want_rc);
        if (want_rc == 0)
            CHECK(v == want_v);
    }
}

static void fixed_cases(void)
{
    char t[40];
    for (int n = 1; n <= 26; n++) { /* 1 to 26 nines, then a blank */
        memset(t, '9', (size_t)n);
        strcpy(t + n, " ");
        fixed_case(t, n <= 18 ? 0 : -1,
                   n <= 18 ? strtoull(t, NULL, 10) : 0);
        memset(t, '0', (size_t)n); /* and zeros */
        strcpy(t + n, "\t");
        fixed_case(t, n <= 18 ? 0 : -1, 0);
    }
    fixed_case("000000000000000001 ", 0, 1);
    fixed_case("123456789012345678\n", 0, 123456789012345678u);
    fixed_case("1234567890123456789 ", -1, 0);
    fixed_case("12345678 ", 0, 12345678);
    fixed_case("1234567 ", 0, 1234567);
    fixed_case("123456789 ", 0, 123456789);
    fixed_case("1234567812345678 ", 0, 1234567812345678u);
    fixed_case("12345678123456789\r", 0, 12345678123456789u);
    fixed_case("7x ", -1, 0);
    fixed_case("7/ ", -1, 0);
    fixed_case("7: ", -1, 0);
    fixed_case("7\xb0 ", -1, 0); /* '0' | 0x80 */
    fixed_case("7\xb9 ", -1, 0);
    fixed_case("1234567: ", -1, 0);
    fixed_case("12345678/ ", -1, 0);
    fixed_case("+7 ", -1, 0); /* the token reader's, not the fast path's */
    fixed_case("-7 ", -1, 0);
    fixed_case(" 7", -1, 0); /* blanks are skipped before the call */
    fixed_case("\n", -1, 0);
    fixed_case("42\f", 0, 42);
    fixed_case("42\v", 0, 42);
}

static void random_cases(void)
{
    static const char after[] = " \t\r\n\f\vx+-.eE/:\xb0\xb9\x80";
    long disagree = 0, taken = 0;
    for (long it = 0; it < 2000000; it++) {
        char s[64];
        size_t n = rnd() % 27, lead = n ? rnd() % (n + 1) : 0;
        if (rnd() % 4)
            lead = 0;
        for (size_t i = 0; i < n; i++)
            s[i] = i < lead ? '0' : (char)('0' + rnd() % 10);
        s[n] = rnd() % 8 ? after[rnd() % (sizeof after - 1)]
                         : (char)(rnd() & 0xff);
        size_t pad = 1 + rnd() % 32;
        int rc;
        uint64_t v;
        disagree += !agree(s, n + 1, pad, &rc, &v);
        taken += rc == 0;
    }
    CHECK(disagree == 0);
    CHECK(taken > 100000); /* the draws do reach accepted tokens */
    printf("random tokens: %ld taken, %ld disagreements\n", taken, disagree);
}

int main(void)
{
    fixed_cases();
    random_cases();
    return check_summary("msh_digits");
}
