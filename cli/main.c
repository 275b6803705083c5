/*
 * main.c -- the getme command: dispatch to a subcommand.
 */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

static const char HELP[] =
    "getme " GETME_VERSION_STRING
    " -- GETMe adaptive mesh smoothing for finite-element meshes\n"
    "\n"
    "usage: getme COMMAND [options]   (getme COMMAND --help for details)\n"
    "\n"
    "commands:\n"
    "  smooth IN -o OUT     smooth a mesh (.msh, .inp, .cgns); only node\n"
    "                       coordinates change, boundaries and interfaces stay\n"
    "  quality IN           mean ratio quality per element type, histogram\n"
    "  distort IN -o OUT    random validity-preserving node moves (for tests)\n"
    "  gmsh MODEL [-3]      mesh a .geo/.step/.msh with Gmsh, then smooth\n"
    "  formats              list the supported file formats\n"
    "  version              print the version\n"
    "\n"
    "examples:\n"
    "  getme smooth part.msh -o part-smooth.msh\n"
    "  getme smooth deck.inp -o deck-smooth.inp --fix LOADED_FACE\n"
    "  getme quality part-smooth.msh\n"
    "\n"
    "exit codes: 0 ok, 1 internal error, 2 usage, 3 cannot read input,\n"
    "4 malformed input, 5 unsupported content, 6 invalid elements in input\n"
    "(--no-untangle), 7 cannot write output, 8 invalid elements that could\n"
    "not be untangled\n";

static void list_format(const getme_format *f)
{
    printf("%-6s %s\n", getme_format_name(f), getme_format_description(f));
}

/* The built-in adapters, then the one the Gmsh plugin adds (cli_open). */
static int list_formats(void)
{
    const getme_format *const *f = getme_formats();
    for (int i = 0; f[i]; i++)
        list_format(f[i]);
    if (cli_gmsh_format())
        list_format(cli_gmsh_format());
    return 0;
}

/* libgomp's threads spin at barriers unless OMP_WAIT_POLICY says otherwise,
   and it reads that variable when the program loads.  On a busy machine (a
   workstation running a GUI, CI running tests side by side) spinning makes
   2 threads many times slower than 1: measured on 191k tets at load 5,
   1.85 s with 1 thread, 23.4 s with 2 spinning, 2.2 s with 2 waiting
   passively.  So unless the user chose a policy, restart once with
   passive waiting; if the restart fails, carry on as we are.
   With thread binding asked for (OMP_PROC_BIND, OMP_PLACES), libgomp has
   already bound this, the initial thread, to the first place before
   main() runs, and execv keeps that mask: the restarted process saw one
   CPU and ran every thread on it (OMP_PROC_BIND=true, 2 threads: twice
   as slow as without binding).  So the restart first widens the mask to
   the union of libgomp's places, which it built from the mask the
   process started with. */
static void prefer_passive_waiting(char **argv)
{
    if (getenv("OMP_WAIT_POLICY"))
        return;
    if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0)
        return;
    cli_affinity_unbind();
    execv("/proc/self/exe", argv);
}

/* glibc serves a large block with mmap() only up to a threshold that
   rises to the size of every such block freed (up to 32 MiB), and then
   serves blocks below it from the heap, whose freed middle parts stay
   resident.  The smoother frees the caller's arrays and its set-up
   temporaries (several MiB each) before its peak, so with the moving
   threshold the peak's resident size was ~20 MiB above its heap on the
   medium hexes (214.8 MiB against 192.9); a fixed 1 MiB threshold returns
   every freed large block to the system (194.7 MiB; ~1 % more CPU for the
   page faults of fresh blocks). */
static void return_freed_memory(void)
{
#ifdef __GLIBC__
    mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
}

int main(int argc, char **argv)
{
    prefer_passive_waiting(argv);
    return_freed_memory();
    if (argc < 2) {
        fputs(HELP, stderr);
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
        fputs(HELP, stdout);
        return 0;
    }
    if (!strcmp(cmd, "--version") || !strcmp(cmd, "version")) {
        printf("getme %s\n", getme_version());
        return 0;
    }
    if (!strcmp(cmd, "smooth"))
        return cli_smooth(argc - 1, argv + 1);
    if (!strcmp(cmd, "quality"))
        return cli_quality(argc - 1, argv + 1);
    if (!strcmp(cmd, "distort"))
        return cli_distort(argc - 1, argv + 1);
    if (!strcmp(cmd, "formats"))
        return list_formats();
    if (!strcmp(cmd, "gmsh"))
        return cli_run_gmsh(argv + 1);
    cli_error("unknown command '%s' (see getme --help)", cmd);
    return EXIT_USAGE;
}
