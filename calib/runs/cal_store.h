// SPDX-License-Identifier: MIT
/// @file cal_store.h
/// The result store of a calibration run: one small YAML record per
/// simulation, named by a hash of the text that defines the simulation
/// (scene, parameters, seed, tier, engine version) and written under a
/// temporary name, then renamed. A killed run leaves whole records or none;
/// a rerun finds every finished simulation and runs only the rest.
#ifndef CAL_STORE_H
#define CAL_STORE_H

#include <stddef.h>

/// What one simulation measured. Drum runs fill the angle/CSA fields,
/// poured cylinders the coordination fields.
typedef struct cal_record {
    char *key;     ///< the defining text (checked on read: no hash collision goes unnoticed)
    char *status;  ///< "ok", "not steady" or "failed"
    char *reason;  ///< why it failed, or ""
    double angle_deg, angle_sd_deg, csa_percent, csa_sd_percent;
    double coordination, coordination_interior, wall_contacts_per_granule, solid_fraction;
    int steady;
    double simulated_time_s, wall_time_s, dt_s, particle_steps;
    double fill_wall_time_s; ///< settling the bed, charged to the first speed turned from it (else 0)
    double peak_rss_mb;      ///< peak resident memory of the process that ran it
    /// A drum turn's smallest network limit over its step, from its checks
    /// (exp_drum_result.dt_margin_min; 0: not checked, or a record older than
    /// the checks), and how often a check lowered the step.
    double dt_margin_min;
    int dt_lowered;
    int granules;
    int retry;               ///< a failure of the process, not of the simulation (killed from
                             ///< outside): valid for the run that wrote it, rerun by any later one
    char *writer;            ///< "host:pid" of the run that wrote it (set by cal_store_put)
} cal_record;

/// 64-bit FNV-1a of the key, as 16 hex digits.
void cal_store_hash(const char *key, char out[17]);

/// Path of a key's record in `dir`.
void cal_store_path(const char *dir, const char *key, char *out, size_t len);

/// Read the record of `key`: 0 found (fields filled, free with
/// cal_record_free), 1 absent, -1 unreadable, damaged or a different key
/// (message). Never changes the store (a plan, a report, a verification).
/// A retry record written by another run counts as absent.
int cal_store_get(const char *dir, const char *key, cal_record *out, char *err, size_t len);

/// cal_store_get for a plan replaying a run: a damaged record counts as
/// absent (1), the simulation the run will make again, and stays where it is.
int cal_store_peek(const char *dir, const char *key, cal_record *out, char *err, size_t len);

/// cal_store_get for a run that simulates what is missing: a damaged record
/// (cut short, not YAML, a field missing) is moved to DIR/damaged/HASH.yaml
/// (kept for inspection, never deleted; a later damaged copy replaces it),
/// one line on stderr says so and that its simulation runs again, and it
/// counts as absent (1). A record of another key stays an error (-1).
int cal_store_lookup(const char *dir, const char *key, cal_record *out, char *err, size_t len);

/// Every record of the store, each handed to visit (the record is freed after
/// the call), in no set order; damaged records and an earlier run's retry
/// records are passed over, and the store is never changed. Returns the
/// records visited (0 where the store does not exist yet), or -1 if the
/// folder cannot be read (message).
int cal_store_each(const char *dir, void (*visit)(const cal_record *r, void *ctx), void *ctx, char *err, size_t len);

/// Write a record atomically. 0 on success.
int cal_store_put(const char *dir, const cal_record *r, char *err, size_t len);

void cal_record_free(cal_record *r);

/// What the record's simulation cost to run, wall seconds: its turn or pour,
/// and the settling charged to it.
double cal_record_cost_s(const cal_record *r);

/// 1 if the record holds a usable measurement (not failed).
int cal_record_usable(const cal_record *r);

#endif
