/* Output files of the commands (JSON, OBJ, logs), written whole or not at all.
 *
 * cli_outfile_open creates a temporary ".NAME.XXXXXX" beside PATH (the same directory, so the
 * rename stays on one file system); the command writes to o->f; cli_outfile_commit flushes,
 * checks and closes it and only then renames it over PATH. Any failure removes the temporary
 * and leaves PATH as it was: an existing file keeps its contents, a symlink named as the
 * output survives. On success the rename replaces the name itself: a symlink at PATH becomes
 * the new file (the file it pointed to is left alone). The new file gets 0666 less the umask,
 * or the mode of the regular file it replaces. The library's writers (PNG, GIF, OBJ, glTF)
 * do the same on their side (src/internal.h, akp_file_atomic). */
#ifndef ANIMKIT_CLI_OUTFILE_H
#define ANIMKIT_CLI_OUTFILE_H

#include <stdio.h>

typedef struct cli_outfile {
    FILE* f;             /* the temporary, open for writing */
    int err;             /* errno of the first failure, 0 when none known */
    char path[4096];     /* the named output */
    char tmp[4096 + 32]; /* the temporary; "" once renamed or removed */
} cli_outfile;

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
