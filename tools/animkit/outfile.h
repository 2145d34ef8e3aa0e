/* Output files of the commands (JSON, OBJ, logs), written whole or not at all: the library's
 * ak_atomic_file (animkit/core.h says how) with the command's messages.
 *
 *     cli_outfile out;
 *     if (cli_outfile_open(&out, "fluid", path)) return CLI_BAD_INPUT;   // message printed
 *     fprintf(out.f, ...);
 *     return cli_outfile_commit(&out, "fluid");                           // or _abort */
#ifndef ANIMKIT_CLI_OUTFILE_H
#define ANIMKIT_CLI_OUTFILE_H

#include <animkit/core.h>

typedef ak_atomic_file cli_outfile;

/* Create the temporary for path. On failure prints "animkit CMD: PATH: cannot create the file
 * (reason)" and returns CLI_BAD_INPUT (nothing created); CLI_OK otherwise. */
int cli_outfile_open(cli_outfile* o, const char* cmd, const char* path);
/* Flush, check, close, rename over the path. On failure removes the temporary, prints
 * "animkit CMD: PATH: cannot write the file (reason)" and returns CLI_BAD_INPUT. */
int cli_outfile_commit(cli_outfile* o, const char* cmd);
/* Give up: close and remove the temporary (the path is not touched). Idempotent; a zeroed
 * cli_outfile is fine. */
void cli_outfile_abort(cli_outfile* o);

#endif
