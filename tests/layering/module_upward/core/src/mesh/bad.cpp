// Fixture for the layering_check test: mesh may not include the session module.
#include "fss/session.h"
