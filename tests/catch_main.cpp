// Catch2's main, compiled once for every test program.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

int main(int argc, char* argv[]) {
  // Enough digits to show any difference between two doubles: a failure never
  // reads "0.0 is within 0.0 of 0.0" (docs/DESIGN.md §4).
  Catch::StringMaker<double>::precision = 17;
  Catch::StringMaker<float>::precision = 9;
  return Catch::Session().run(argc, argv);
}
