// Catch2's main, compiled once for every test program (Catch2 3.x or 2.13:
// tests/support/catch.h).
#if CL_CATCH2_MAJOR >= 3
#include <catch2/catch_session.hpp>
#include <catch2/catch_tostring.hpp>
#else
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>
#endif

int main(int argc, char* argv[]) {
  // Enough digits to show any difference between two doubles: a failure never
  // reads "0.0 is within 0.0 of 0.0" (docs/DESIGN.md §4).
  Catch::StringMaker<double>::precision = 17;
  Catch::StringMaker<float>::precision = 9;
  return Catch::Session().run(argc, argv);
}
