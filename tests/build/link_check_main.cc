// The program of the layers' link checks (tests/build/CMakeLists.txt): it calls nothing; its
// executables exist to link one layer's whole library with only the layers below it.
int main() { return 0; }
