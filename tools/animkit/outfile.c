/* Output files written whole or not at all (outfile.h): ak_atomic_file with messages. */
#include "outfile.h"

#include <errno.h>
#include <string.h>

#include "cli.h"

int cli_outfile_open(cli_outfile* o, const char* cmd, const char* path) {
    if (ak_atomic_file_open(o, path) != AK_OK)
        return cli_fail(cmd, "%s: cannot create the file (%s)", path, strerror(o->err ? o->err : EIO));
    return CLI_OK;
}

int cli_outfile_commit(cli_outfile* o, const char* cmd) {
    if (ak_atomic_file_commit(o) == AK_OK) return CLI_OK;
    return cli_fail(cmd, "%s: cannot write the file (%s)", o->path, strerror(o->err ? o->err : EIO));
}

void cli_outfile_abort(cli_outfile* o) { ak_atomic_file_abort(o); }
