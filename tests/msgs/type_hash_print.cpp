// Prints quadcosim's REP-2016 type hash (dds/type_hash.hpp) of each type named on the command line, one
// "pkg/msg/Type RIHS01_<hex>" line each, for type_hashes.py to check against its own computation.
#include <exception>
#include <iostream>

#include "dds/type_hash.hpp"

int main(int argc, char** argv) {
  try {
    for (int i = 1; i < argc; ++i) std::cout << argv[i] << ' ' << quadcosim::dds::type_hash(argv[i]) << '\n';
  } catch (const std::exception& e) {
    std::cerr << "type_hash_print: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
