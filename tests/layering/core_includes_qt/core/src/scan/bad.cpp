// Fixture for the layering_check test: core never includes Qt.
#include <QString>
