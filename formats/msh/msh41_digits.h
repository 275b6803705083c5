/*
 * msh41_digits.h -- a decimal integer token, eight digits per step (the
 * ASCII fast path's node and element tags, msh41_fast.c).
 *
 * A digit at a time costs a branch per digit whose count changes from
 * token to token (tags of 1 to 7 digits in one element line), and those
 * mispredictions were most of the element lines' cost.  Here eight bytes
 * are loaded at once, the digits among them found by bit tests on all
 * eight, and their value formed by three multiplications (the method of
 * fast_float's parse_eight_digits_unrolled): no branch per digit.
 *
 * The result is the scalar loop's exactly: the same value for 1 to 18
 * digits (leading zeros included), and -1 (refused) for no digit, for 19
 * or more, and for a token not followed by a blank or a newline.
 */
#ifndef MSH41_DIGITS_H
#define MSH41_DIGITS_H

#include <stdint.h>
#include <string.h>

#define MSH41_DIGITS_MAX 18 /* longer tokens: the token reader's */

static inline int msh41_is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

/* The reference: one digit at a time, needs nothing past the token's end
   (the end of a run). */
static inline int msh41_digits_scalar(const char *s, const char **after,
                                      uint64_t *v)
{
    const char *d = s;
    uint64_t x = 0;
    for (; *s >= '0' && *s <= '9'; s++) {
        if (s - d == MSH41_DIGITS_MAX)
            return -1;
        x = 10 * x + (uint64_t)(*s - '0');
    }
    if (s == d || !(msh41_is_blank(*s) || *s == '\n'))
        return -1;
    *v = x;
    *after = s;
    return 0;
}

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/* x: eight bytes, the first in the low bits, each XOR '0' (a digit is
   then 0-9).  How many leading bytes are digits (0-8): a byte is not one
   if its high nibble is set or its low nibble + 6 carries into bit 4
   (neither test carries into the next byte). */
static inline int msh41_digit_run8(uint64_t x)
{
    uint64_t bad = (x & 0xF0F0F0F0F0F0F0F0u) |
                   (((x & 0x0F0F0F0F0F0F0F0Fu) + 0x0606060606060606u) &
                    0x1010101010101010u);
    return bad ? __builtin_ctzll(bad) >> 3 : 8;
}

/* The value of the first n (1-8) digits of x (as above): shifted to the
   top (zeros before them are leading zeros), then pairs, quadruples and
   the whole by multiplications that cannot carry between the parts. */
static inline uint64_t msh41_digits_value8(uint64_t x, int n)
{
    x <<= 8 * (8 - n);
    x = x * 10 + (x >> 8);
    x = (((x & 0x000000FF000000FFu) * 0x000F424000000064u) +
         (((x >> 16) & 0x000000FF000000FFu) * 0x0000271000000001u)) >> 32;
    return (uint32_t)x;
}

/* The token at s (no blanks before it); end: readable bytes end there.
   Eight-byte steps while 24 bytes are readable (three steps cover the 19
   digits that refuse), else the scalar loop. */
static inline int msh41_digits(const char *s, const char *end,
                               const char **after, uint64_t *v)
{
    static const uint64_t pow10[9] = {1,      10,      100,      1000,
                                      10000,  100000,  1000000,  10000000,
                                      100000000};
    if (end - s < 24)
        return msh41_digits_scalar(s, after, v);
    uint64_t x = 0;
    int n = 0, k;
    do {
        uint64_t w;
        memcpy(&w, s + n, 8);
        w ^= 0x3030303030303030u;
        k = msh41_digit_run8(w);
        if (k)
            x = x * pow10[k] + msh41_digits_value8(w, k);
        n += k;
    } while (k == 8 && n < 24);
    if (n == 0 || n > MSH41_DIGITS_MAX ||
        !(msh41_is_blank(s[n]) || s[n] == '\n'))
        return -1;
    *v = x;
    *after = s + n;
    return 0;
}
#else
static inline int msh41_digits(const char *s, const char *end,
                               const char **after, uint64_t *v)
{
    (void)end;
    return msh41_digits_scalar(s, after, v);
}
#endif

#endif /* MSH41_DIGITS_H */
