/*
 * main.c -- the getme command: dispatch to a subcommand.
 */
#include "cli.h"

#include <string.h>

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
    "4 malformed input, 5 unsupported content, 6 invalid elements in input,\n"
    "7 cannot write output\n";

static int list_formats(void)
{
    const getme_format *const *f = getme_formats();
    for (int i = 0; f[i]; i++)
        printf("%-6s %s\n", f[i]->name, f[i]->description);
    return 0;
}

int main(int argc, char **argv)
{
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
    if (!strcmp(cmd, "gmsh")) {
#ifdef GETME_HAVE_CLI_GMSH
        return getme_cli_gmsh(argc - 1, argv + 1);
#else
        cli_error("this getme was built without the Gmsh plugin");
        return GETME_IO_ERR_UNSUPPORTED;
#endif
    }
    cli_error("unknown command '%s' (see getme --help)", cmd);
    return EXIT_USAGE;
}
