// SPDX-License-Identifier: MIT
// Turn a settled drum bed with a checkpoint (see exp_drum_turn.h).
#include "exp_drum_turn.h"

#include <stdio.h>

// What the turn tells about its checkpoint: one not resumed, or the resume
// and the wall time it saved.
static void tell_checkpoint(const exp_drum_turn *t, const exp_drum_result *r)
{
    if (r->checkpoint_note[0]) fprintf(stderr, "%s %s\n", t->log_prefix, r->checkpoint_note);
    if (r->resumed)
        fprintf(stderr, "%s %g rpm: resumed from its checkpoint %s (%.0f s of wall time saved)\n", t->log_prefix,
                t->run.rpm, t->checkpoint_path, r->earlier_wall_s);
}

dem_world *exp_drum_turn_bed(dem_world *bed, int own, const exp_drum_turn *t, exp_drum_result *out,
                             dem_status *status)
{
    dem_world *w = own ? bed : dem_world_clone(bed);
    if (!w) return NULL;
    exp_drum_run_opts run = t->run;
    exp_drum_checkpoint ck = {t->checkpoint_path, t->key, t->checkpoint_every_s, t->checkpoint_at_end};
    run.checkpoint = ck.every_s > 0 ? &ck : NULL;
    double t0 = exp_wall_seconds();
    *status = exp_drum_rotate(w, t->def, &run, t->progress, t->progress_ctx, out);
    // A resumed turn's clock started at its checkpoint: add what came before.
    out->wall_time_s = exp_wall_seconds() - t0 + out->earlier_wall_s;
    if (t->progress_line_open) fputc('\n', stderr);
    tell_checkpoint(t, out);
    return w;
}
