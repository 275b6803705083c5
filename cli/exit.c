/*
 * exit.c -- libgetme_formats' status codes -> the getme command's exit
 * codes (cli.h), which scripts rely on and tests check.
 */
#include "cli.h"

int cli_exit_code(getme_formats_status st)
{
    switch (st) {
    case GETME_FORMATS_OK: return CLI_EXIT_OK;
    case GETME_FORMATS_ERR_OPEN: return CLI_EXIT_OPEN;
    case GETME_FORMATS_ERR_PARSE: return CLI_EXIT_PARSE;
    case GETME_FORMATS_ERR_UNSUPPORTED: return CLI_EXIT_UNSUPPORTED;
    case GETME_FORMATS_ERR_INVALID: return CLI_EXIT_INVALID;
    case GETME_FORMATS_ERR_WRITE: return CLI_EXIT_WRITE;
    case GETME_FORMATS_ERR_ARGUMENT: return EXIT_USAGE;
    case GETME_FORMATS_ERR_INTERNAL: return CLI_EXIT_INTERNAL;
    }
    return CLI_EXIT_INTERNAL;
}
