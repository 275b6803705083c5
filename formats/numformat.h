/*
 * numformat.h -- double to "%.*g" text without printf for the common case
 * (private to libgetme_formats; numformat.c says why it is exact).
 */
#ifndef GETME_NUMFORMAT_H
#define GETME_NUMFORMAT_H

/* snprintf(buf, 32, "%.*g", prec, v) in the C locale, 1 <= prec <= 17: the
   same text and length for every v.  If roundtrip is not NULL, *roundtrip
   gets 1 if the text reads back to v (strtod), else 0. */
int numformat_g(double v, int prec, char *buf, int *roundtrip);

#endif /* GETME_NUMFORMAT_H */
