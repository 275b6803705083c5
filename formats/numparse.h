/*
 * numparse.h -- exact decimal text to double without strtod for the common
 * case (private to libgetme_formats; numparse.c says why it is exact).
 */
#ifndef GETME_NUMPARSE_H
#define GETME_NUMPARSE_H

/* A drop-in for strtod(s, end) in the C locale: the same value, end and
   errno for every input.  Plain decimals ([+-]digits[.digits][e[+-]digits],
   at most 19 significant digits, followed by the end of the string, a
   space or a comma) whose value can be formed by one exact IEEE operation
   are converted here; everything else goes to strtod. */
double numparse_strtod(const char *s, char **end);

#endif /* GETME_NUMPARSE_H */
