// Fixture for the layering_check test: widgets never include core's private headers.
#include "stitch/stitch_stages.h"
