# cmake -DIN=<file> -DOUT=<source.cc> -DFUNC=<name> -P embed_file.cmake
# Writes a C++ source defining std::string_view posefilter::view::<name>() that returns the
# bytes of <file> (the viewer's inlined scripts, src/view/assets.h).
file(READ "${IN}" hex HEX)
string(LENGTH "${hex}" hex_len)
math(EXPR size "${hex_len} / 2")
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
file(WRITE "${OUT}.tmp"
  "// Generated from ${IN} by cmake/embed_file.cmake; do not edit.\n"
  "#include \"view/assets.h\"\n"
  "namespace posefilter::view {\n"
  "namespace { const unsigned char kBytes[] = {${bytes}0}; }\n"
  "std::string_view ${FUNC}() { return {reinterpret_cast<const char*>(kBytes), ${size}}; }\n"
  "}  // namespace posefilter::view\n")
file(RENAME "${OUT}.tmp" "${OUT}")
