/* Shared between the web build's own files (web/). Never installed. */
#ifndef ANIMKIT_WEB_H
#define ANIMKIT_WEB_H

#include "view_app.h"

/* The fluid presets as a viewer plug-in (web/fluid_sim.c): "fluid", "fluid:preset:NAME". */
extern const view_sim web_fluid_sim;

#endif
