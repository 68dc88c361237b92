// SPDX-License-Identifier: MIT
/// @file exp_yaml.h
/// Loading a YAML file against a libcyaml schema with an error message a
/// user can act on: "FILE:LINE: FIELD: what is wrong". libcyaml reports the
/// problem and a backtrace (field, line) through its log callback; this
/// collects them into one line.
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

#endif
