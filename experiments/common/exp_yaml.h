// SPDX-License-Identifier: MIT
/// @file exp_yaml.h
/// Loading a YAML file against a libcyaml schema with an error message a
/// user can act on: "FILE:LINE: FIELD: what is wrong". libcyaml reports the
/// problem and a backtrace (field, line) through its log callback; this
/// collects them into one line. The same located messages for the checks a
/// config's loader makes after reading it: exp_field_error, exp_message_field,
/// exp_yaml_line_of.
#ifndef EXP_YAML_H
#define EXP_YAML_H

#include <cyaml/cyaml.h>
#include <stddef.h>

/// Load `path` into *out. 0 on success; else 1 with the message in err.
/// `hint` (may be NULL) is appended to schema errors, e.g. "see configs/drum.yaml".
int exp_yaml_load(const char *path, const cyaml_schema_value_t *schema, void **out, const char *hint, char *err,
                  size_t len);

/// Free what exp_yaml_load loaded.
void exp_yaml_free(const cyaml_schema_value_t *schema, void *data);

/// 1 if the file's first line that is not blank or a comment starts with
/// `first` (e.g. "experiment: drum"): how `granucal simulate` tells its
/// experiment configs apart.
int exp_yaml_starts_with(const char *path, const char *first);

/// Line (1-based) on which `key:` first appears in a file at or after
/// `from_line`, or 0: used to point messages at the offending line when the
/// YAML library reports only the field.
int exp_yaml_line_of(const char *path, const char *key, int from_line);

/// The field a check's message starts with ("granule_contact.mu_s = -1: ...",
/// "walls[0].contact.mu_s = ..."): its whole path into `field`, and, returned,
/// its last component (a pointer into `field`), the key to look up in the file.
enum { EXP_FIELD_LEN = 64 };
const char *exp_message_field(const char *msg, char field[EXP_FIELD_LEN]);

/// The error for a config field whose value is bad, pointed at where the value
/// came from: "PATH: --set FIELD=V: MSG" when the last `--set` of that field
/// (among sets[0..n_sets)) gave it, else "PATH:LINE: FIELD: MSG" at the field's
/// line in the file ("PATH: FIELD: MSG" if the line is not found). Always 1.
int exp_field_error(const char *path, int n_sets, char *const *sets, const char *field, const char *msg, char *err,
                    size_t len);

/// A config's `seed`: the definitions hold it as a uint64_t, so a negative one
/// (it would wrap) is refused at its line in the file (`--set seed=` refuses
/// one itself, exp_apply_set). 0, or 1 with the located error.
int exp_seed_check(const char *path, int seed, char *err, size_t len);

#endif
