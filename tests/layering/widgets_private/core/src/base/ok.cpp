// Fixture for the layering_check test: a valid core file, so that only the widget include fails.
#include "fss/error.h"
