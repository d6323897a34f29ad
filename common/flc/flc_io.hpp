#pragma once
// Reading and writing controllers: Aerie's YAML (config/flc/*.yaml, the rule tables
// as the thesis prints them) and fuzzylite's FLL, the reference engine's format.
//
// FLL has no scaling factors, so the export folds them into the variables: an input
// set at position c of a variable with factor K becomes a triangle peaking at c/K in
// raw units (range [min/K, max/K], saturated with lock-range), an output set becomes a
// Constant K_u * c. fuzzylite then computes exactly eq. 5.1 on raw inputs (Constant
// terms, WeightedAverage, AlgebraicProduct conjunction, no aggregation). The factors
// are also written in a comment line ("# aerie-flc scaling: ...") so that import
// restores the scaled parametrisation; an FLL without it imports with factors 1.
#include <string>

#include "common/flc/flc.hpp"

namespace aerie::flc {

// YAML. Errors (std::runtime_error) name the origin (file) and the key/line.
FlcSpec parse_yaml(const std::string& text, const std::string& origin = "<string>");
FlcSpec load_yaml(const std::string& path);
std::string to_yaml(const FlcSpec& spec);
void save_yaml(const FlcSpec& spec, const std::string& path);

// FLL (fuzzylite 6). Import accepts the subset that eq. 5.1 covers and refuses the
// rest with a reason (other term shapes, norms, defuzzifiers, hedges, "or").
std::string to_fll(const FlcSpec& spec);
// FLL text longer than this is refused before it is parsed (FLC_PARAMS, --controller files).
inline constexpr size_t kMaxFllBytes = size_t{1} << 20;
FlcSpec parse_fll(const std::string& text, const std::string& origin = "<string>");
FlcSpec load_fll(const std::string& path);
void save_fll(const FlcSpec& spec, const std::string& path);

// Loads .yaml/.yml or .fll by extension.
FlcSpec load_controller(const std::string& path);

// The initial controller of thesis 5.1.3 (Tables 5.1-5.5, the reconstructed sets of
// Figs. 5.6-5.9, all factors and weights 1), from config/flc/initial.yaml compiled in.
FlcSpec thesis_initial();
const char* thesis_initial_yaml();

}  // namespace aerie::flc
