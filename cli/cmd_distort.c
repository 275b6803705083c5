/*
 * cmd_distort.c -- `getme distort IN -o OUT --seed S`: random,
 * validity-preserving moves of free nodes (for tests and benchmarks).
 */
#include "cli.h"

#include <stdlib.h>
#include <string.h>

static const char DISTORT_HELP[] =
    "usage: getme distort IN -o OUT --seed S [--amount A] [--rounds N]\n"
    "                     [--target-qmean Q] [-q]\n"
    "\n"
    "Move every free node by a random vector of up to A times its shortest\n"
    "incident edge (default A = 0.5), keeping each element valid (q > 1e-4),\n"
    "for N rounds (default 1) or until qmean <= Q (then up to 100 rounds).\n"
    "Deterministic for a seed. Fixed nodes follow the same rules as smooth.\n";

int cli_distort(int argc, char **argv)
{
    cli_log log = {0, 0};
    const char *input = NULL, *output = NULL;
    long seed = -1, rounds = -1;
    double amount = 0.5, target = 0.0;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            fputs(DISTORT_HELP, stdout);
            return 0;
        } else if (!strcmp(o, "-o") || !strcmp(o, "--output")) {
            if (!v) {
                cli_error("-o needs a file name");
                return EXIT_USAGE;
            }
            output = v, i++;
        } else if (!strcmp(o, "--seed")) {
            if (cli_parse_int(o, v, 0, 2147483647L, &seed) != 0)
                return EXIT_USAGE;
            i++;
        } else if (!strcmp(o, "--rounds")) {
            if (cli_parse_int(o, v, 0, 100000, &rounds) != 0)
                return EXIT_USAGE;
            i++;
        } else if (!strcmp(o, "--amount")) {
            if (cli_parse_double(o, v, &amount) != 0)
                return EXIT_USAGE;
            if (!(amount > 0.0)) {
                cli_error("--amount must be > 0");
                return EXIT_USAGE;
            }
            i++;
        } else if (!strcmp(o, "--target-qmean")) {
            if (cli_parse_double(o, v, &target) != 0)
                return EXIT_USAGE;
            i++;
        } else if (!strcmp(o, "-q") || !strcmp(o, "--quiet")) {
            log.quiet = 1;
        } else if (o[0] == '-' && o[1]) {
            cli_error("unknown option '%s' (see getme distort --help)", o);
            return EXIT_USAGE;
        } else if (!input) {
            input = o;
        } else {
            cli_error("unexpected argument '%s'", o);
            return EXIT_USAGE;
        }
    }
    if (!input || !output || seed < 0) {
        cli_error("getme distort needs IN, -o OUT and --seed S "
                  "(see getme distort --help)");
        return EXIT_USAGE;
    }
    if (rounds < 0)
        rounds = target > 0.0 ? 100 : 1;
    cli_paths paths = {input, output, NULL, "", ""};
    int st = cli_check_paths(&paths);
    if (st)
        return st;
    getme_doc *doc = cli_open(input, NULL, 0, &st, &log);
    if (!doc)
        return st;
    if ((st = cli_check_read_files(&paths, doc)) != 0) {
        getme_doc_close(doc);
        return st;
    }
    getme_mesh *mesh = getme_doc_mesh(doc);
    getme_quality_stats s;
    cli_print_stats(&log, "Quality before", getme_doc_stats(doc));
    if (getme_mesh_distort(mesh, (uint64_t)seed, amount, target, (int)rounds) !=
        GETME_OK) {
        cli_error("%s: %s", input, getme_mesh_error(mesh));
        getme_doc_close(doc);
        return CLI_EXIT_INTERNAL;
    }
    getme_mesh_quality_stats(mesh, -1, &s);
    cli_print_stats(&log, "Quality after ", &s);
    cli_guard guard = {0};
    cli_write_guard(&guard, 1);
    st = cli_exit_code(getme_doc_write(doc, paths.out));
    cli_write_guard(&guard, 0);
    if (st != CLI_EXIT_OK)
        cli_error("%s", getme_doc_error(doc));
    else
        cli_info(&log, "Done writing '%s'", output);
    getme_doc_close(doc);
    return st;
}
