// Fixture for the format_check test: deliberately not formatted.
int   unformatted ( int x ){return x+1 ;}
