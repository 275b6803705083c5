/*
 * inp_hash.c -- the two open-addressing tables of the INP adapter:
 * int64 -> int32 (sparse ids, set and part names by scope) and a
 * case-insensitive string table (Abaqus labels are case-insensitive).
 */
#include "inp_internal.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

#define EMPTY INT64_MIN

static uint64_t mix64(uint64_t x)
{
    /* splitmix64 finaliser: consecutive ids land far apart, so linear
       probing stays short even for dense numbering. */
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    x ^= x >> 31;
    return x;
}

static int hash_grow(inp_hash *h)
{
    size_t ncap = h->cap ? h->cap * 2 : 64;
    int64_t *keys = getme__malloc(ncap * sizeof *keys);
    int32_t *vals = getme__malloc(ncap * sizeof *vals);
    if (!keys || !vals) {
        free(keys);
        free(vals);
        return -1;
    }
    for (size_t i = 0; i < ncap; i++)
        keys[i] = EMPTY;
    for (size_t i = 0; i < h->cap; i++) {
        if (h->keys[i] == EMPTY)
            continue;
        size_t j = mix64((uint64_t)h->keys[i]) & (ncap - 1);
        while (keys[j] != EMPTY)
            j = (j + 1) & (ncap - 1);
        keys[j] = h->keys[i];
        vals[j] = h->vals[i];
    }
    free(h->keys);
    free(h->vals);
    h->keys = keys;
    h->vals = vals;
    h->cap = ncap;
    return 0;
}

int inp_hash_put(inp_hash *h, int64_t key, int32_t val, int32_t *old)
{
    if (2 * (h->count + 1) > h->cap && hash_grow(h))
        return -1;
    size_t j = mix64((uint64_t)key) & (h->cap - 1);
    while (h->keys[j] != EMPTY) {
        if (h->keys[j] == key) {
            if (old)
                *old = h->vals[j];
            return 1;
        }
        j = (j + 1) & (h->cap - 1);
    }
    h->keys[j] = key;
    h->vals[j] = val;
    h->count++;
    return 0;
}

int32_t inp_hash_get(const inp_hash *h, int64_t key)
{
    if (!h->cap)
        return -1;
    size_t j = mix64((uint64_t)key) & (h->cap - 1);
    while (h->keys[j] != EMPTY) {
        if (h->keys[j] == key)
            return h->vals[j];
        j = (j + 1) & (h->cap - 1);
    }
    return -1;
}

void inp_hash_free(inp_hash *h)
{
    free(h->keys);
    free(h->vals);
    memset(h, 0, sizeof *h);
}

/* ---- strings ------------------------------------------------------------ */

static uint64_t name_hash(const char *s)
{
    uint64_t x = 1469598103934665603ULL; /* FNV-1a over upper-cased bytes */
    for (; *s; s++) {
        int c = (unsigned char)*s;
        if (c >= 'a' && c <= 'z')
            c -= 32;
        x = (x ^ (uint64_t)c) * 1099511628211ULL;
    }
    return x;
}

static size_t str_slot(const inp_strtab *t, const char *s, int *found)
{
    size_t j = name_hash(s) & (t->nslots - 1);
    *found = 0;
    while (t->slots[j]) {
        if (inp_name_eq(t->arena + t->offs[t->slots[j] - 1], s)) {
            *found = 1;
            break;
        }
        j = (j + 1) & (t->nslots - 1);
    }
    return j;
}

static int str_rehash(inp_strtab *t)
{
    size_t n = t->nslots ? t->nslots * 2 : 64;
    int32_t *slots = getme__calloc(n, sizeof *slots);
    if (!slots)
        return -1;
    free(t->slots);
    t->slots = slots;
    t->nslots = n;
    for (size_t id = 0; id < t->count; id++) {
        int found;
        size_t j = str_slot(t, t->arena + t->offs[id], &found);
        t->slots[j] = (int32_t)id + 1;
    }
    return 0;
}

int32_t inp_str_find(const inp_strtab *t, const char *s)
{
    if (!t->nslots)
        return -1;
    int found;
    size_t j = str_slot(t, s, &found);
    return found ? t->slots[j] - 1 : -1;
}

int32_t inp_str_intern(inp_strtab *t, const char *s)
{
    int32_t id = inp_str_find(t, s);
    if (id >= 0)
        return id;
    if (t->count >= INT32_MAX - 1)
        return -1;
    if (2 * (t->count + 1) > t->nslots && str_rehash(t))
        return -1;
    size_t n = strlen(s) + 1;
    if (INP_RESERVE(t->arena, t->cap, t->len + n) ||
        INP_RESERVE(t->offs, t->cap_offs, t->count + 1))
        return -1;
    memcpy(t->arena + t->len, s, n);
    t->offs[t->count] = t->len;
    t->len += n;
    int found;
    size_t j = str_slot(t, s, &found);
    t->slots[j] = (int32_t)t->count + 1;
    return (int32_t)t->count++;
}

const char *inp_str(const inp_strtab *t, int32_t id)
{
    if (id < 0 || (size_t)id >= t->count)
        return "";
    return t->arena + t->offs[id];
}

void inp_strtab_free(inp_strtab *t)
{
    free(t->arena);
    free(t->offs);
    free(t->slots);
    memset(t, 0, sizeof *t);
}
