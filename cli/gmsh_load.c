/*
 * gmsh_load.c -- the Gmsh plugin, loaded only when a command needs it.
 *
 * libgetme_gmsh pulls in libgmsh and, through it, OpenCASCADE, FLTK and a
 * hundred more libraries: linked into the getme command they added 46 MiB
 * to the resident size of every run (55.8 against 9.7 MiB for `getme
 * --version`) and a few tenths of a second of start-up, also for
 * `getme smooth` of a file the native readers take, which never calls
 * Gmsh.  So the command loads the plugin with dlopen() the first time a
 * file reaches its adapter (an MSH file the native reader declines, a
 * file no built-in adapter takes) or `getme formats` lists it, and
 * `getme gmsh` runs in its own program, getme-gmsh (gmsh_main.c).
 */
#define _GNU_SOURCE /* dladdr-free /proc/self/exe readlink, RTLD flags */
#include "cli.h"

#include "getme_formats_adapter.h"

#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#ifdef GETME_HAVE_CLI_GMSH
/* The folder of the running program (with a trailing '/'), or "". */
static void program_dir(char *dir, size_t size)
{
    ssize_t n = readlink("/proc/self/exe", dir, size - 1);
    dir[n > 0 ? n : 0] = '\0';
    char *slash = strrchr(dir, '/');
    if (slash)
        slash[1] = '\0';
    else
        dir[0] = '\0';
}
#endif

const getme_format *cli_gmsh_format(void)
{
#ifdef GETME_HAVE_CLI_GMSH
    static const getme_format *real;
    static int tried;
    if (tried)
        return real;
    tried = 1;
    /* The installed layout (the program's folder, then the library folder
       beside it), then the build tree's plugin, then the loader's search. */
    char dir[PATH_MAX], path[PATH_MAX + 64];
    program_dir(dir, sizeof dir);
    const char *where[] = {GETME_GMSH_BIN_TO_LIB, NULL, GETME_GMSH_SONAME};
    void *h = NULL;
    for (int i = 0; i < 3 && !h; i++) {
        if (i == 0)
            snprintf(path, sizeof path, "%s%s/%s", dir, where[0],
                     GETME_GMSH_SONAME);
        else if (i == 1)
            snprintf(path, sizeof path, "%s", GETME_GMSH_BUILD_PATH);
        else
            snprintf(path, sizeof path, "%s", where[2]);
        h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    }
    const getme_format *(*get)(void) = NULL;
    if (h)
        *(void **)&get = dlsym(h, "getme_gmsh_format");
    real = get ? get() : NULL;
    return real;
#else
    return NULL;
#endif
}

/* The adapter cli_open hands getme_doc_open: forwards to the plugin's,
   loading it when getme_doc_open first asks (its probe).  Its name, the
   description and the extensions are the plugin's once loaded, which is
   before a document can have been opened with it. */
static int lazy_probe(const char *path);
static getme_formats_status lazy_open(getme_doc *doc,
                                      const getme_doc_options *opts);
static getme_formats_status lazy_write(getme_doc *doc, const char *out);
static void lazy_close(getme_doc *doc);
static const char *lazy_file(const getme_doc *doc, size_t i);

static getme_format lazy = {"gmsh", "", lazy_probe, lazy_open, lazy_write,
                            lazy_close, "", lazy_file};

static const getme_format *load(void)
{
    const getme_format *f = cli_gmsh_format();
    if (f) {
        lazy.name = f->name;
        lazy.description = f->description;
        lazy.extensions = f->extensions;
    }
    return f;
}

static int lazy_probe(const char *path)
{
    const getme_format *f = load();
    return f && f->probe(path);
}

/* Only reached after lazy_probe loaded the plugin. */
static getme_formats_status lazy_open(getme_doc *doc,
                                      const getme_doc_options *opts)
{
    return load()->open(doc, opts);
}

static getme_formats_status lazy_write(getme_doc *doc, const char *out)
{
    return load()->write(doc, out);
}

static void lazy_close(getme_doc *doc)
{
    const getme_format *f = load();
    if (f && f->close)
        f->close(doc);
}

static const char *lazy_file(const getme_doc *doc, size_t i)
{
    const getme_format *f = load();
    return f && f->file ? f->file(doc, i) : NULL;
}

const getme_format *cli_gmsh_adapter(void)
{
#ifdef GETME_HAVE_CLI_GMSH
    return &lazy;
#else
    return NULL;
#endif
}

int cli_run_gmsh(char **argv)
{
#ifdef GETME_HAVE_CLI_GMSH
    char dir[PATH_MAX], path[PATH_MAX + 16];
    program_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%sgetme-gmsh", dir);
    argv[0] = path;
    execv(path, argv);
    cli_error("cannot run %s for `getme gmsh`", path);
    return CLI_EXIT_INTERNAL;
#else
    (void)argv;
    cli_error("this getme was built without the Gmsh plugin");
    return CLI_EXIT_UNSUPPORTED;
#endif
}
