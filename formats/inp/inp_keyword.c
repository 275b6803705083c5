/*
 * inp_keyword.c -- Abaqus keyword lines: "*ELEMENT, TYPE=C3D8, ELSET=Bolt".
 * Keyword and parameter names are case-insensitive and blanks in them are
 * ignored ("*Solid Section" = "*SOLIDSECTION"); values keep their spelling
 * (file names are case-sensitive), with blanks around them and enclosing
 * double quotes removed.  A line ending with a comma continues on the next.
 */
#include "inp_internal.h"

#include <stdio.h>
#include <string.h>

/* Upper-case s[0..n) without blanks into out (size sz); -1 if too long. */
static int squeeze(const char *s, size_t n, char *out, size_t sz)
{
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        int c = (unsigned char)s[i];
        if (c == ' ' || c == '\t' || c == '\r')
            continue;
        if (c >= 'a' && c <= 'z')
            c -= 32;
        if (k + 1 >= sz)
            return -1;
        out[k++] = (char)c;
    }
    out[k] = '\0';
    return 0;
}

static int add_param(inp_keyword *kw, const inp_field *f, int64_t offset,
                     const char *line, char *err, size_t errsz)
{
    if (f->n == 0)
        return 0; /* ",," or a trailing comma */
    const char *eq = memchr(f->s, '=', f->n);
    size_t klen = eq ? (size_t)(eq - f->s) : f->n;
    if (kw->nparams == INP_MAX_PARAMS) {
        snprintf(err, errsz, "more than %d parameters on *%s", INP_MAX_PARAMS,
                 kw->name);
        return -1;
    }
    inp_param *p = &kw->p[kw->nparams];
    if (squeeze(f->s, klen, p->key, sizeof p->key) || !p->key[0]) {
        snprintf(err, errsz, "bad parameter name on *%s", kw->name);
        return -1;
    }
    const char *v = eq ? eq + 1 : f->s + f->n;
    const char *ve = f->s + f->n;
    while (v < ve && (*v == ' ' || *v == '\t'))
        v++;
    p->line_offset = offset;
    p->val_col = (int)(v - line);
    p->val_len = (int)(ve - v);
    if (ve - v >= 2 && *v == '"' && ve[-1] == '"') {
        v++;
        ve--;
    }
    if ((size_t)(ve - v) >= INP_MAX_VALUE) {
        snprintf(err, errsz, "value of %s= on *%s longer than %d characters",
                 p->key, kw->name, INP_MAX_VALUE - 1);
        return -1;
    }
    memcpy(p->val, v, (size_t)(ve - v));
    p->val[ve - v] = '\0';
    if (memchr(p->val, '\0', (size_t)(ve - v))) {
        snprintf(err, errsz, "NUL byte in the value of %s=", p->key);
        return -1;
    }
    kw->nparams++;
    return 0;
}

int inp_keyword_parse(inp_keyword *kw, const char *text, size_t len,
                      int64_t offset, int first, char *err, size_t errsz)
{
    const char *p = text, *end = text + len;
    inp_field f;
    int last = 0;
    if (first) {
        memset(kw, 0, offsetof(inp_keyword, p));
        while (p < end && *p != '*')
            p++;
        p++; /* the '*' (inp_line_kind made sure there is one) */
        inp_next_field(&p, end, &f, &last);
        if (squeeze(f.s, f.n, kw->name, sizeof kw->name) || !kw->name[0]) {
            snprintf(err, errsz, "bad keyword '%.40s'", text);
            return -1;
        }
        kw->continued = 0;
        if (last)
            return 0;
    }
    kw->continued = 0;
    while (inp_next_field(&p, end, &f, &last)) {
        if (last && f.n == 0) {
            kw->continued = 1; /* trailing comma */
            break;
        }
        if (add_param(kw, &f, offset, text, err, errsz))
            return -1;
    }
    return 0;
}

const inp_param *inp_keyword_param(const inp_keyword *kw, const char *key)
{
    for (int i = kw->nparams - 1; i >= 0; i--)
        if (strcmp(kw->p[i].key, key) == 0)
            return &kw->p[i];
    return NULL;
}

const char *inp_keyword_get(const inp_keyword *kw, const char *key)
{
    const inp_param *p = inp_keyword_param(kw, key);
    return p ? p->val : NULL;
}
