// calibrate --case: the candidates of calibration/effects.hpp as calibration.json describes them
// (docs/schemas/calibration.schema.json): kind, name, location (the place's names and figures),
// parameters in the units their keys name, scores, and the hint that would tell two apart.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "calibration/calibrate.hpp"

namespace tt::io {

/// The place of `c` with the names of `names`: a heat input's centre, box, area, groups and body;
/// a film's group (groups, when one share of h acts on several); a source and its body; a
/// material and field; a sensor; an air's convection groups.
nlohmann::json location_json(const calibration::Candidate& c, const calibration::Naming& names);

/// The description of a fitted candidate in calibration.json (`effects`, `runners_up`): kind, name,
/// location, parameters (a per-run air's per training run, with where its air came from, and a
/// claimed air's per test run), scores, `unphysical` when it is, the refit, `claimed`.
nlohmann::json effect_json(const calibration::ReportedEffect& e, const calibration::Naming& names);
/// ... of `fit` of `cat`'s candidate.
nlohmann::json effect_json(const calibration::Catalogue& cat, const calibration::EffectFit& fit,
                           bool claimed);

/// calibration.json's `ambiguous`: per ambiguity, {candidates: [two effect_json],
/// score_difference, spread, distinguishing_channel {channel, rms_difference_sigmas}, hint}.
nlohmann::json ambiguity_json(const calibration::ReportedAmbiguity& a,
                              const calibration::Naming& names);
/// ... of every Selection::ambiguous of `sel` made on `cat`.
nlohmann::json ambiguity_json(const calibration::Catalogue& cat, const calibration::Selection& sel);

/// calibration.json's `pairs` entry: {candidates: [two descriptions with the joint parameters],
/// score, heldout_gain, heldout_gain_per_training_run, adds_to_second_alone, adds_to_first_alone,
/// admissible}.
nlohmann::json pair_json(const calibration::ReportedPair& p, const calibration::Naming& names);

/// What measurement would tell candidates `a` and `b` apart (the `hint` of `ambiguous`).
std::string telling_apart(const calibration::Candidate& a, const calibration::Candidate& b,
                          const calibration::Naming& names);

}  // namespace tt::io
