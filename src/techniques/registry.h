/* registry.h -- the one table of techniques, and parameter handling that
 * every front end shares: defaults, "name=value" parsing with typed range
 * checks, and formatting. Errors name the parameter and its valid range. */
#ifndef SL_REGISTRY_H
#define SL_REGISTRY_H
#include <stdio.h>
#include "techniques/technique.h"

int tech_count(void);
const Technique *tech_at(int i);
/* NULL and an error listing the known names when absent. */
const Technique *tech_find(const char *name, Error *err);

/* Fill values with every parameter's default. */
void tech_params_default(const Technique *t, double *values);
/* Parse "name=value" into values; unknown names and out-of-range or
 * ill-typed values are refused with the parameter's range. */
bool tech_param_parse(const Technique *t, const char *assignment, double *values, Error *err);
/* Set one parameter by name from a number (ints, bools and enum indices too). */
bool tech_param_set(const Technique *t, const char *name, double value, double *values, Error *err);
int tech_param_index(const Technique *t, const char *name);
/* Check a whole value array as tech_param_set would each value (finite,
 * integral where the type says so, in range): library callers that fill
 * values directly are refused by parameter name and range, before any work. */
bool tech_params_check(const Technique *t, const double *values, Error *err);
/* The value as text: enum names, true/false, integers, %.9g floats. */
void tech_param_format(const ParamDesc *p, double value, char *out, size_t n);
/* The valid range as text: "[1, 64]", "one of: a, b", "true or false". */
void tech_param_range(const ParamDesc *p, char *out, size_t n);
const char *param_type_name(ParamType t);
/* The technique's light kinds as text ("point, spot, sphere"). */
void tech_lights_text(const Technique *t, char *out, size_t n);
/* Refuse a light the technique does not handle, naming what it handles. */
bool tech_check_light(const Technique *t, const Light *light, int light_number, Error *err);
/* Parameter k's condition (ParamCondition.when): the technique's own, else
 * the shared map block's (smap_conditions); NULL when it always acts. */
const char *tech_param_when(const Technique *t, int k);
/* Does parameter k act under these values: its condition holds, or it has none? A parameter that does not act changes no output, so
 * the configuration key leaves it out. */
bool tech_param_acts(const Technique *t, int k, const double *values);
/* Can parameter k's condition hold at all within the technique's ranges (a
 * shared map parameter that acts only under warps, in a technique that takes
 * no warps, cannot), and does its range hold two values? One that cannot or
 * does not is not the technique's: `list`, the docs and the Lua
 * descriptions leave it out, and setting it to anything but its default is
 * refused by name (its default is accepted: records and round trips name
 * every parameter). */
bool tech_param_offered(const Technique *t, int k);
/* Set the parameters that parameter k's condition names so that its first
 * possible alternative holds (the registry-wide parameter test varies k there). */
void tech_param_enable(const Technique *t, int k, double *values);
/* Refuse a malformed condition: unknown names, values outside a range. */
bool tech_param_condition_check(const Technique *t, int k, Error *err);
/* Does the technique declare resource kind `kind` (Technique.resources)? */
bool tech_acquires(const Technique *t, const char *kind);

#endif
