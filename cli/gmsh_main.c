/*
 * gmsh_main.c -- getme-gmsh, the program `getme gmsh ...` runs (execv,
 * gmsh_load.c): the one part of the command that calls Gmsh itself, so
 * the only one linked with libgmsh.
 */
#include "cli.h"

int main(int argc, char **argv)
{
    /* getme_cli_gmsh reads its options from argv[1] on, as after "gmsh" */
    return getme_cli_gmsh(argc, argv);
}
