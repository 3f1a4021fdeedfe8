// Donor of the tests' precompiled header (test_pch.h); see tests/CMakeLists.txt. An executable, so the
// header is built with the executables' flags (-fPIE), which every test that reuses it must share.
int main() {
    return 0;
}
