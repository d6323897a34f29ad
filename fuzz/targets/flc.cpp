// Controller import (common/flc/flc_io.hpp) on the input as a controller file: fuzzylite's FLL
// (parse_fll, what aerie-control --controller and FLC_PARAMS carry) and Aerie's YAML (parse_yaml),
// both on every input. A controller a reader accepts is compiled (flc::Flc validates it and
// builds the rule table), evaluated, and must be written in the same format and read back.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "common/flc/flc.hpp"
#include "common/flc/flc_io.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

using namespace aerie;

void compile_and_write_back(const flc::FlcSpec& spec, const char* format, std::string (*write)(const flc::FlcSpec&),
                            flc::FlcSpec (*read)(const std::string&, const std::string&)) {
  const flc::Flc controller(spec);
  for (const double x : {-1e3, -1.0, 0.0, 0.5, 1e3}) controller.evaluate(x, -x, 0.5 * x);
  controller.evaluate(NAN, 0, 0);
  const std::string text = write(spec);
  try {
    flc::Flc again(read(text, "written"));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "a controller read from %s does not read back from what it writes: %s\n%s\n", format, e.what(),
                 text.c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  const std::string text = fuzz::as_text(data, size);
  fuzz::refusal_ok([&] { compile_and_write_back(flc::parse_fll(text, "input.fll"), "FLL", flc::to_fll, flc::parse_fll); });
  fuzz::refusal_ok([&] { compile_and_write_back(flc::parse_yaml(text, "input.yaml"), "YAML", flc::to_yaml, flc::parse_yaml); });
  return 0;
}
