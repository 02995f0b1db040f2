/*
 * api/model_up — the automatic choice behind a model object's "up": "auto" (and
 * `umbra-render thumb --up auto`): whether a model with no convention of its own stands on its
 * y or its z axis, from where it would touch the ground.
 *
 * The rule: for each of +y and +z, the share of the model's surface (every instance, in the
 * model's space) that lies flat on its lowest plane along that axis, facing down (normal within
 * ~25 degrees of -axis, all three corners within 1 % of the extent of that plane). A part
 * printed or machined from a plate, a statue on its base, a figure on its feet: their bottom
 * touches the ground across a flat face. z is chosen when its contact share is over 2 % of the
 * surface and more than twice y's; else y, the default (a model with no flat bottom either way
 * stays as the file has it). glTF files are +y by their specification: "auto" keeps +y.
 * Pure; any thread.
 */
#ifndef UMBRA_API_MODEL_UP_H
#define UMBRA_API_MODEL_UP_H

#include "model.h"

/* The chosen up axis: 'y' or 'z'. contact_y, contact_z (may be NULL): the two shares. */
char api_model_auto_up(const struct api_model *m, double *contact_y, double *contact_z);

#endif
