// Speed of our FLC engine against fuzzylite (the reference engine) on the same
// controllers and the same random inputs; checks on the way that both agree to 1e-9.
//   bench_flc [--out DIR] [--evaluations N]
// Prints ns per evaluation and the ratio; writes DIR/flc_speed.csv and .json.
#include <fl/Headers.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>

#include "common/flc/flc.hpp"
#include "common/flc/flc_io.hpp"
#include "common/flc/prune.hpp"

using namespace aerie;

namespace {

flc::FlcSpec thesis_optimised() {
  flc::FlcSpec s = flc::thesis_initial();
  s.id = "thesis-sfmf";
  for (const auto& [n, v] : std::vector<std::pair<std::string, double>>{{"Kp", 4.6739}, {"Kd", 0.03}, {"Ki", -0.5003},
                                                                         {"error.Left", -89.696}, {"derivative.Negative", -8.1166},
                                                                         {"integral.Negative", -9.9782}, {"yaw_rate.BigLeft", -88.974},
                                                                         {"yaw_rate.Left", -88.191}, {"yaw_rate.LittleLeft", -74.952}})
    s.set_parameter(n, v);
  return s;
}

template <typename F>
double best_ns_per_eval(int repeats, size_t n, F&& body) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    body();
    const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
    best = std::min(best, ns / static_cast<double>(n));
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_flc: aerie_flc vs fuzzylite evaluation speed (same FLL, same inputs)"};
  std::string out = "bench-out/flc";
  size_t n = 20000;
  app.add_option("--out", out, "output folder");
  app.add_option("--evaluations", n, "random inputs per controller");
  CLI11_PARSE(app, argc, argv);
  std::filesystem::create_directories(out);
  fl::fuzzylite::setMachEps(0.0);  // exact comparisons, as eq. 5.1 (see tests/common/flc)

  struct Row {
    std::string controller;
    size_t rules;
    double ours_ns, fuzzylite_ns, max_diff;
  };
  std::vector<Row> rows;
  for (const flc::FlcSpec& spec : {flc::thesis_initial(), thesis_optimised(), flc::prune(thesis_optimised())}) {
    const flc::Flc ours(spec);
    std::unique_ptr<fl::Engine> engine(fl::FllImporter().fromString(flc::to_fll(spec)));
    std::mt19937_64 rng(1);
    std::vector<std::array<double, 3>> x(n);
    for (auto& v : x)
      for (int i = 0; i < 3; ++i) {
        const auto& var = spec.inputs[i];
        const double half = 0.75 * (var.max - var.min) / std::abs(var.scaling);
        v[i] = std::uniform_real_distribution<double>(-half, half)(rng);
      }
    std::vector<double> a(n), b(n);
    fl::InputVariable* in[3] = {engine->getInputVariable(0), engine->getInputVariable(1), engine->getInputVariable(2)};
    fl::OutputVariable* o = engine->getOutputVariable(0);
    const double t_ours = best_ns_per_eval(7, n, [&] {
      for (size_t k = 0; k < n; ++k) a[k] = ours.evaluate(x[k][0], x[k][1], x[k][2]);
    });
    const double t_fl = best_ns_per_eval(3, n, [&] {
      for (size_t k = 0; k < n; ++k) {
        for (int i = 0; i < 3; ++i) in[i]->setValue(x[k][i]);
        engine->process();
        b[k] = o->getValue();
      }
    });
    double diff = 0;
    for (size_t k = 0; k < n; ++k) diff = std::max(diff, std::abs(a[k] - b[k]));
    rows.push_back({spec.id, spec.rules.size(), t_ours, t_fl, diff});
    std::printf("%-22s %3zu rules: aerie_flc %8.1f ns/eval, fuzzylite %9.1f ns/eval, ratio %6.1fx, max |diff| %.2e\n",
                spec.id.c_str(), spec.rules.size(), t_ours, t_fl, t_fl / t_ours, diff);
    if (diff > 1e-9) {
      std::fprintf(stderr, "outputs differ by %g > 1e-9\n", diff);
      return 1;
    }
  }
  std::ofstream csv(out + "/flc_speed.csv"), json(out + "/flc_speed.json");
  csv << "controller,rules,aerie_ns_per_eval,fuzzylite_ns_per_eval,ratio,max_abs_diff\n";
  json << "[\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    csv << r.controller << "," << r.rules << "," << r.ours_ns << "," << r.fuzzylite_ns << "," << r.fuzzylite_ns / r.ours_ns << ","
        << r.max_diff << "\n";
    json << "  {\"controller\": \"" << r.controller << "\", \"rules\": " << r.rules << ", \"aerie_ns_per_eval\": " << r.ours_ns
         << ", \"fuzzylite_ns_per_eval\": " << r.fuzzylite_ns << ", \"ratio\": " << r.fuzzylite_ns / r.ours_ns
         << ", \"max_abs_diff\": " << r.max_diff << "}" << (i + 1 < rows.size() ? "," : "") << "\n";
  }
  json << "]\n";
  std::printf("wrote %s/flc_speed.csv and .json\n", out.c_str());
  return 0;
}
