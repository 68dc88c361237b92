// SPDX-License-Identifier: MIT
/// @file exp_common.h
/// Shared pieces of the virtual experiments (prefix exp_).
#ifndef EXP_COMMON_H
#define EXP_COMMON_H

/// Version string of the experiments layer (part of every result hash).
const char *exp_version(void);

#endif
