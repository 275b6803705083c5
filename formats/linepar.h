/*
 * linepar.h -- parse a run of text lines on several threads (private to
 * libgetme_formats; linepar.c says how it stays deterministic).
 */
#ifndef GETME_LINEPAR_H
#define GETME_LINEPAR_H

#include <stddef.h>

/* Parse the line at line, the index-th of the run (the text goes on to
   end and its last byte is a '\n'): the start of the next line if it was
   taken, or NULL if it is not a line the fast path handles (the caller's
   serial reader then takes that line, with its own messages). */
typedef const char *(*linepar_fn)(void *ctx, const char *line,
                                  const char *end, size_t index);

/* Parse at most max lines of text[0..len) with fn (len ends a line: the
   text's last byte is a '\n'), split at line boundaries into pieces for
   threads threads.  fn must write only what belongs to its index.  Returns how
   many lines come before the first refused one in text order (all, up to
   max, if none), whatever the thread count: lines after a refused one may
   have been parsed too, and the caller ignores what they wrote.  *bytes
   gets the length of the lines taken. */
size_t linepar_run(const char *text, size_t len, size_t max, int threads,
                   linepar_fn fn, void *ctx, size_t *bytes);

/* The pieces linepar_run hands its threads, for callers that run their
   own (inp_write_nodes.c): the first max lines of text[0..len) (len ends
   a line) cut at line starts into at most np pieces of about equal bytes
   (np <= LINEPAR_MAX_PIECES).  cut[0..*ncut] are the pieces' bounds (cut[0]
   = text, cut[*ncut] the end of the run), first[k] the index of piece k's
   first line (first[*ncut] = the run's line count, also returned). */
#define LINEPAR_MAX_PIECES 64
size_t linepar_pieces(const char *text, size_t len, size_t max, int np,
                      const char **cut, size_t *first, int *ncut);

/* The number of '\n' in [p, end). */
size_t linepar_count(const char *p, const char *end);

/* Threads for a run of len bytes: 1 below a size where starting threads
   costs more than it saves, else threads (at least 1). */
int linepar_threads(int threads, size_t len);

#endif /* GETME_LINEPAR_H */
