/*
 * test_alloc.c -- the allocation functions of core/alloc/getme_alloc.h:
 * each gives a block that works as the C library's does (zeroed by calloc,
 * kept by realloc), and a block of GETME_HUGE_MIN bytes or more starts on
 * a huge-page boundary and lies in memory advised for huge pages (the "hg"
 * flag in /proc/self/smaps, which madvise(MADV_HUGEPAGE) sets), while a
 * smaller one and a plain malloc of the same size do not (so the check
 * itself can fail); calloc'd blocks only from GETME_HUGE_CALLOC_MIN on,
 * where the C library puts them.  Built with
 * -DGETME_HUGE_PAGES=OFF, no block is advised.  Skipped (exit 77) where
 * the kernel has no transparent huge pages.
 */
#include "check.h"
#include "getme_alloc.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Does the mapping that holds address p carry VmFlags flag (two letters)?
   -1 if /proc/self/smaps has no mapping for it. */
static int vma_has_flag(const void *p, const char *flag)
{
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f)
        return -1;
    char line[512];
    int inside = 0, found = -1;
    uintptr_t a = (uintptr_t)p;
    while (fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        char dash;
        if (sscanf(line, "%lx%c%lx ", &lo, &dash, &hi) == 3 && dash == '-') {
            inside = a >= lo && a < hi;
            continue;
        }
        if (inside && strncmp(line, "VmFlags:", 8) == 0) {
            found = 0;
            for (const char *s = line + 8; *s; s++)
                if (s[0] == flag[0] && s[1] == flag[1] &&
                    (s[-1] == ' ') && (s[2] == ' ' || s[2] == '\n'))
                    found = 1;
            break;
        }
    }
    fclose(f);
    return found;
}

static int advised(const void *p, size_t n)
{
    return vma_has_flag((const char *)p + n / 2, "hg") == 1;
}

static int huge_aligned(const void *p)
{
    return (uintptr_t)p % GETME_HUGE_PAGE == 0;
}

int main(void)
{
    FILE *thp = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (!thp) {
        printf("skipped: no transparent huge pages in this kernel\n");
        return 77;
    }
    fclose(thp);
#ifdef GETME_NO_HUGE_PAGES
    const int want = 0;
#else
    const int want = 1;
#endif
    const size_t big = 2 * GETME_HUGE_MIN, small = GETME_HUGE_MIN / 4;

    /* small first, while nothing around it has been advised */
    unsigned char *s = getme__malloc(small);
    CHECK(s != NULL);
    memset(s, 0x5a, small);
    CHECK(!advised(s, small));

    unsigned char *plain = malloc(big);
    CHECK(plain != NULL);
    CHECK(vma_has_flag(plain + big / 2, "hg") == 0); /* the check sees it */

    unsigned char *m = getme__malloc(big);
    CHECK(m != NULL);
    CHECK(advised(m, big) == want);
    memset(m, 0xa5, big);
    CHECK(m[0] == 0xa5 && m[big - 1] == 0xa5);
    /* the partial pages at both ends too: advice that left out the first
       page split a large block's mapping in two, and glibc's realloc
       could then no longer grow it in place (mremap failed, EFAULT) */
    CHECK(vma_has_flag(m, "hg") == want);
    CHECK(vma_has_flag(m + big - 1, "hg") == want);
    CHECK(huge_aligned(m) == want);

    /* between one huge page and the calloc threshold: a malloc'd block is
       aligned and advised (it holds one whole huge page), a calloc'd one
       neither (its untouched pages stay the kernel's zero page) */
    const size_t mid = GETME_HUGE_MIN + GETME_HUGE_MIN / 2;
    CHECK(mid < GETME_HUGE_CALLOC_MIN);
    unsigned char *mm = getme__malloc(mid);
    CHECK(mm != NULL);
    CHECK(huge_aligned(mm) == want && advised(mm, mid) == want);
    memset(mm, 0x3c, mid);
    CHECK(mm[mid - 1] == 0x3c);
    unsigned char *mc = getme__calloc(mid, 1);
    CHECK(mc != NULL);
    CHECK(!advised(mc, mid) && mc[0] == 0 && mc[mid - 1] == 0);

    size_t k = big / sizeof(double);
    double *c = getme__calloc(k, sizeof *c);
    CHECK(c != NULL);
    CHECK(advised(c, big) == want);
    int zero = 1;
    for (size_t i = 0; i < k; i += 509)
        zero &= c[i] == 0.0;
    CHECK(zero && c[k - 1] == 0.0);

    void *al = getme__aligned_alloc(64, big);
    CHECK(al != NULL && (uintptr_t)al % 64 == 0);
    CHECK(advised(al, big) == want && huge_aligned(al) == want);

    /* grown from the small block: its bytes kept, the new block advised */
    unsigned char *r = getme__realloc(s, big);
    CHECK(r != NULL);
    CHECK(r[0] == 0x5a && r[small - 1] == 0x5a);
    CHECK(advised(r, big) == want && huge_aligned(r) == want);

    /* a large block grown: its bytes kept, the whole block advised */
    m = getme__realloc(m, 2 * big);
    CHECK(m != NULL);
    CHECK(m[0] == 0xa5 && m[big - 1] == 0xa5);
    CHECK(vma_has_flag(m, "hg") == want && advised(m, 2 * big) == want);
    CHECK(huge_aligned(m) == want);
    /* shrunk: its bytes kept */
    unsigned char *m2 = getme__realloc(m, big / 2);
    CHECK(m2 != NULL && m2[0] == 0xa5 && m2[big / 2 - 1] == 0xa5);
    m = m2;

    free(plain);
    free(mm);
    free(mc);
    free(m);
    free(c);
    free(al);
    free(r);
    return check_summary("alloc");
}
