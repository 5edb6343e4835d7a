// Umbrella include for the runtime: load a .kanim and sample it.
#pragma once
#include "keyanim/cardinal.h"
#include "keyanim/clip.h"
#include "keyanim/skeleton.h"
#include "keyanim/status.h"
#include "keyanim/version.h"
