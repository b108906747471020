// `volscissors version`: prints the version and the libraries it was built with.
#include <iostream>

#include "command.h"

namespace {
const vs::cli::Registration reg{"version", "print version information", [](CLI::App&) -> vs::cli::Runner {
                                  return [] {
                                    std::cout << "volscissors 0.1.0 (C++20; ITK image I/O, Eigen, CLI11)\n";
                                    return 0;
                                  };
                                }};
}
