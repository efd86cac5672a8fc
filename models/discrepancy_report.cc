#include "models/discrepancy_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "models/discrepancy.h"
#include "models/discrepancy_uncertainty.h"
#include "models/effect_catalogue.h"

namespace airtwin {
namespace discrepancy_detail {

std::string fixed(double x, int decimals) {
  if (!std::isfinite(x)) return "n/a";
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, x);
  return text;
}

}  // namespace discrepancy_detail

using discrepancy_detail::fixed;

std::string discrepancy_report_json(const DiscrepancyReport& r) {
  using Json = nlohmann::ordered_json;
  auto num = [](double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); };
  // An extension's typed values as {key: value}, catalogue order.
  auto params_of = [](const std::string& name, const std::vector<double>& v) {
    const EffectSpec& spec = find_effect(name);
    Json params = Json::object();
    for (size_t i = 0; i < v.size(); ++i) params[spec.params[i].key] = v[i];
    return params;
  };
  auto candidate = [&](const CandidateResult& c) {
    return Json{{"name", c.name},
                {"params", params_of(c.name, c.params)},
                {"heldout_end_mape", num(c.heldout_end_mape)},
                {"delta_bic", num(c.delta_bic)},
                {"p_value", num(c.p_value)},
                {"heldout_path_error", num(c.heldout_path_error)},
                {"gain", num(c.gain)},
                {"heldout_cost", num(c.heldout_cost)},
                {"relevant", c.relevant},
                {"end_mape_improves", c.end_mape_improves},
                {"significant", c.significant},
                {"shown_by", c.shown_by},
                {"shown_gain", num(c.shown_gain)},
                {"selection_frequency", c.selection_frequency},
                {"fit_evaluations", c.fit_evaluations},
                {"fit_screen_evaluations", c.fit_screen_evaluations}};
  };
  Json j;
  j["baseline_end_mape"] = num(r.baseline_end_mape);
  Json found = Json::array();
  if (r.decidable && r.found.empty()) found.push_back("none");
  for (const std::string& f : r.found) found.push_back(f);
  j["found"] = found;
  j["unexplained"] = r.unexplained;
  Json cands = Json::array();
  for (const CandidateResult& c : r.candidates) cands.push_back(candidate(c));
  j["candidates"] = cands;
  j["extended_end_mape"] = num(r.extended_end_mape);
  j["gain_pct"] = num(r.gain_pct);
  j["decidable"] = r.decidable;
  j["notes"] = r.notes;
  Json ext = Json::object();
  for (const std::string& name : r.found) {
    ext[name] = params_of(name, extension_values(r.extensions, name));
  }
  j["extensions"] = ext;
  Json intervals = Json::object();
  for (const auto& [name, ranges] : r.intervals) {
    const EffectSpec& spec = find_effect(name);
    Json params = Json::object();
    for (size_t i = 0; i < ranges.size(); ++i) {
      params[spec.params[i].key] = Json::array({num(ranges[i].lo), num(ranges[i].hi)});
    }
    intervals[name] = params;
  }
  j["intervals"] = intervals;
  j["nuisance"] = {{"static_friction_ratio", num(r.nuisance_static_friction_ratio)}};
  Json rounds = Json::array();
  for (const auto& round : r.rounds) {
    Json rr = Json::array();
    for (const CandidateResult& c : round) rr.push_back(candidate(c));
    rounds.push_back(rr);
  }
  j["rounds"] = rounds;
  j["none_frequency"] = r.none_frequency;
  Json backward = Json::array();
  for (const BackwardCheck& b : r.backward) {
    backward.push_back({{"name", b.name},
                        {"others", b.others},
                        {"delta_bic", num(b.delta_bic)},
                        {"p_value", num(b.p_value)},
                        {"gain", num(b.gain)},
                        {"end_mape_improves", b.end_mape_improves},
                        {"kept", b.kept},
                        {"shown_by", b.shown_by}});
  }
  j["backward"] = backward;
  Json exchanges = Json::array();
  for (const Exchange& e : r.exchanges) {
    exchanges.push_back({{"removed", e.removed},
                         {"added", e.added},
                         {"heldout_cost_before", num(e.cost_before)},
                         {"heldout_cost_after", num(e.cost_after)},
                         {"accepted", e.accepted}});
  }
  j["exchanges"] = exchanges;
  Json rivals = Json::array();
  for (const Rival& v : r.rivals) {
    rivals.push_back({{"cause", v.cause},
                      {"rival", v.rival},
                      {"params", params_of(v.rival, v.params)},
                      {"p_value", num(v.p_value)},
                      {"cause_delta_bic", num(v.cause_delta_bic)},
                      {"rival_delta_bic", num(v.rival_delta_bic)},
                      {"cause_gain", num(v.cause_gain)},
                      {"rival_gain", num(v.rival_gain)}});
  }
  j["rivals"] = rivals;
  Json alternative = Json::array();
  for (const AlternativeRoute& a : r.alternative) {
    alternative.push_back({{"round", a.round},
                           {"lead", a.lead},
                           {"provisional", a.provisional},
                           {"p_value", num(a.p_value)},
                           {"found_first", a.found_first},
                           {"found_other", a.found_other},
                           {"heldout_cost_first", num(a.cost_first)},
                           {"heldout_cost_other", num(a.cost_other)},
                           {"taken", a.taken}});
  }
  j["alternative"] = alternative;
  Json pairs = Json::array();
  for (const PairEntry& e : r.pairs) {
    pairs.push_back({{"round", e.round},
                     {"first", e.first},
                     {"second", e.second},
                     {"delta_bic", num(e.delta_bic)},
                     {"p_value", num(e.p_value)},
                     {"gain", num(e.gain)},
                     {"end_mape_improves", e.end_mape_improves},
                     {"significant", e.significant}});
  }
  j["pairs"] = pairs;
  j["provisional"] = r.provisional;
  j["withdrawn"] = r.withdrawn;
  j["joint_p_value"] = num(r.joint_p_value);
  j["baseline_end_mape_all"] = num(r.baseline_end_mape_all);
  j["baseline_path_error"] = num(r.baseline_path_error);
  j["extended_path_error"] = num(r.extended_path_error);
  j["baseline_path_error_cm"] = {{"mean", num(r.baseline_path_error_cm_mean)},
                                 {"max", num(r.baseline_path_error_cm_max)}};
  Json bins = Json::object();
  for (const auto& [name, list] : r.residual_bins) {
    Json arr = Json::array();
    for (const ResidualBin& b : list) {
      arr.push_back({{"lo", b.lo},
                     {"hi", b.hi},
                     {"n", b.n},
                     {"radial_cm", num(b.radial_cm)},
                     {"tangential_cm", num(b.tangential_cm)},
                     {"norm_cm", num(b.norm_cm)}});
    }
    bins[name] = arr;
  }
  j["residual_structure"] = bins;
  Json corrections = Json::array();
  for (const ResidualCorrection& c : r.corrections) {
    corrections.push_back({{"feature", c.feature},
                           {"unit", c.unit},
                           {"bandwidth", c.bandwidth},
                           {"cv_gain", num(c.cv_gain)},
                           {"heldout_gain", num(c.heldout_gain)},
                           {"p_value", num(c.p_value)},
                           {"heldout_rms_mps2", num(c.heldout_rms_mps2)},
                           {"where", c.where}});
  }
  j["what_is_left"] = {
      {"unexplained", r.unexplained},
      {"n_acceleration_samples", r.n_acceleration_samples},
      {"median_residual_mps2",
       {{"radial", num(r.median_residual_radial)}, {"across", num(r.median_residual_across)}}},
      {"chosen", r.chosen_correction >= 0
                     ? Json(r.corrections[static_cast<size_t>(r.chosen_correction)].feature)
                     : Json(nullptr)},
      {"corrections", corrections}};
  j["n_trajectories"] = r.n_trajectories;
  j["n_windows"] = r.n_windows;
  j["n_train_windows"] = r.n_train_windows;
  j["n_heldout_windows"] = r.n_heldout_windows;
  j["n_mape_windows"] = r.n_mape_windows;
  j["tilts_deg"] = r.tilts_deg;
  j["source"] = r.source;
  return j.dump(2) + "\n";
}

std::string discrepancy_correction_csv(const DiscrepancyReport& r) {
  std::string csv = "x,y,radial_mps2,across_mps2,weight\n";
  if (r.chosen_correction < 0) return csv;
  const ResidualCorrection& c = r.corrections.at(static_cast<size_t>(r.chosen_correction));
  char line[160];
  for (int j = 0; j < c.ny; ++j) {
    for (int i = 0; i < c.nx; ++i) {
      const size_t k = static_cast<size_t>(j * c.nx + i);
      std::snprintf(line, sizeof(line), "%.4f,%.4f,%.5g,%.5g,%.5g\n", c.x0 + i * c.step,
                    c.ny > 1 ? c.y0 + j * c.step : 0.0, c.radial[k], c.across[k], c.weight[k]);
      csv += line;
    }
  }
  return csv;
}

std::string discrepancy_report_markdown(const DiscrepancyReport& r) {
  std::string md = "# Discrepancy analysis: " + r.source + "\n\n";
  md += "Data: " + std::to_string(r.n_trajectories) + " trajectories, " +
        std::to_string(r.n_windows) + " windows (" + std::to_string(r.n_train_windows) +
        " for fitting, " + std::to_string(r.n_heldout_windows) + " held out); tilts:";
  // Appendix D's few tilts each; a closed-loop log's hundreds as their range.
  constexpr std::size_t kTiltsListed = 8;
  if (r.tilts_deg.size() <= kTiltsListed) {
    for (double t : r.tilts_deg) {
      md += ' ';  // piecewise: GCC 12 reports a false -Wrestrict on " " + std::string
      md += fixed(t, 1);
    }
  } else {
    md += ' ';
    md += std::to_string(r.tilts_deg.size()) + " distinct, " + fixed(r.tilts_deg.front(), 1) +
          " to " + fixed(r.tilts_deg.back(), 1);
  }
  md += " deg.\n\n## What is wrong\n\n";
  md +=
      "The nominal model (field table, eq. (8) coefficients, nozzle response) predicts the "
      "held-out windows with an end-position MAPE of " +
      fixed(r.baseline_end_mape, 1) + " % (all windows: " + fixed(r.baseline_end_mape_all, 1) +
      " %); its path error is " + fixed(r.baseline_path_error_cm_mean, 1) + " cm on average, " +
      fixed(r.baseline_path_error_cm_max, 1) + " cm at worst.\n\n";
  md +=
      "## Where\n\nMean residual (prediction minus measurement, cm) along the radial direction "
      "from s and across it (counter-clockwise positive):\n\n";
  for (const auto& [name, bins] : r.residual_bins) {
    md += "| " + name + " | n | radial | across | length |\n|---|---|---|---|---|\n";
    for (const ResidualBin& b : bins) {
      if (b.n == 0) continue;
      md += "| " + fixed(b.lo, 2) + " to " + fixed(b.hi, 2) + " | " + std::to_string(b.n) + " | " +
            fixed(b.radial_cm, 2) + " | " + fixed(b.tangential_cm, 2) + " | " +
            fixed(b.norm_cm, 2) + " |\n";
    }
    md += "\n";
  }
  md += "Plots: residuals_*.png.\n\n## Why\n\n";
  if (!r.decidable) {
    md += "Nothing can be decided from these data:\n\n";
    for (const std::string& n : r.notes) md += "- " + n + "\n";
    return md;
  }
  md +=
      "Each candidate cause was fitted on the training windows and scored on the held-out ones "
      "(a cause needs delta BIC <= -10, a Wilcoxon p below the Bonferroni level and at least a "
      "15 % lower held-out path error)";
  if (std::isfinite(r.nuisance_static_friction_ratio)) {
    md += ", each on top of an ordinary static friction fitted with it (static / kinetic " +
          fixed(r.nuisance_static_friction_ratio, 3) +
          " here: a nuisance that eq. (8)'s start condition ignores, not a cause)";
  }
  md += ":\n\n";
  md +=
      "| candidate | parameters | held-out end MAPE % | path error gain % | delta BIC | p | cause? "
      "| chosen in resamples % |\n"
      "|---|---|---|---|---|---|---|---|\n";
  for (const CandidateResult& c : r.candidates) {
    ModelExtensions e;
    set_extension_values(&e, c.name, c.params);
    md += "| " + c.name + " | " + describe_extension(e, c.name).substr(c.name.size() + 2) + " | " +
          fixed(c.heldout_end_mape, 1) + " | " + fixed(100.0 * c.gain, 1) + " | " +
          fixed(c.delta_bic, 1) + " | " +
          (c.p_value < 1e-4 ? std::string("< 1e-4") : fixed(c.p_value, 4)) + " | " +
          (c.significant ? (c.shown_by.empty() ? std::string("yes")
                                               : "yes, in " + c.shown_by + " (" +
                                                     fixed(100.0 * c.shown_gain, 1) + " %)")
                         : std::string("no")) +
          " | " + fixed(100.0 * c.selection_frequency, 0) + " |\n";
  }
  md += "\n";
  if (std::any_of(r.candidates.begin(), r.candidates.end(),
                  [](const CandidateResult& c) { return !c.shown_by.empty(); })) {
    md +=
        "\"yes, in E\": the pooled held-out windows pass the signed-rank test and keep their end "
        "MAPE, and experiment E's own windows show the size (its path-error gain in brackets), "
        "which the pooled windows, mostly of other experiments, do not.\n\n";
  }
  if (!r.none_frequency.empty()) {
    md += "The last column: of " + std::to_string(discrepancy_detail::kSelectionResamples) +
          " resamples of the training and held-out windows (the fits held), how often the same "
          "rule adds the candidate in the first round; none in " +
          fixed(100.0 * r.none_frequency.front(), 0) + " %.\n\n";
  }
  if (r.found.empty() && !r.withdrawn.empty()) {
    std::string names;
    for (const std::string& w : r.withdrawn) names += (names.empty() ? "" : ", ") + w;
    md += "**None**: " + names +
          " passed the rule against the model with an ordinary static friction fitted, but the "
          "extended model as written is worse than the nominal one on the held-out windows (see "
          "the notes), so it is withdrawn.\n\n";
  } else if (r.found.empty()) {
    md +=
        "**None** of the candidates explains the discrepancy better than chance: what remains "
        "is scatter (e.g. turbulence), not a missing cause.\n\n";
  } else {
    md += "Found, in order:\n\n";
    for (const std::string& f : r.found) {
      md += "- **" + describe_extension(r.extensions, f) + "**: " + find_effect(f).cause + ".";
      const auto it = r.intervals.find(f);
      if (it != r.intervals.end()) {
        const EffectSpec& spec = find_effect(f);
        md += " 95 % bootstrap intervals:";
        bool at_resolution = false;
        for (size_t i = 0; i < it->second.size(); ++i) {
          const ParameterRange& iv = it->second[i];
          md += std::string(i == 0 ? " " : ", ") + spec.params[i].key + " " + fixed(iv.lo, 3) +
                " to " + fixed(iv.hi, 3);
          if (iv.hi - iv.lo <= iv.resolution * (1 + 1e-9)) {
            md += "*";
            at_resolution = true;
          }
        }
        md += ".";
        if (at_resolution) {
          md +=
              " (*: every resample refitted within the fit's finest step; the interval is that "
              "resolution.)";
        }
      }
      for (const Rival& v : r.rivals) {
        if (v.cause != f) continue;
        ModelExtensions e;
        set_extension_values(&e, v.rival, v.params);
        md += " The held-out windows cannot tell it from **" + describe_extension(e, v.rival) +
              "** (its path errors are not the lower ones: signed-rank p " + fixed(v.p_value, 3) +
              "; path error gain " + fixed(100.0 * v.cause_gain, 1) + " against " +
              fixed(100.0 * v.rival_gain, 1) +
              " %): either explains these data, and the training windows chose it (delta BIC " +
              fixed(v.cause_delta_bic, 1) + " against " + fixed(v.rival_delta_bic, 1) + ").";
      }
      md += "\n";
    }
    md += "\n";
  }
  auto names_of = [](const std::vector<std::string>& v) {
    std::string t;
    for (const std::string& n : v) t += (t.empty() ? "" : ", ") + n;
    return t.empty() ? std::string("none") : t;
  };
  const bool any_taken = std::any_of(r.alternative.begin(), r.alternative.end(),
                                     [](const AlternativeRoute& a) { return a.taken; });
  for (const AlternativeRoute& a : r.alternative) {
    md += "- The other route: in round " + std::to_string(a.round) + " a cause was found while " +
          a.lead +
          (a.provisional ? ", better supported by the training windows, failed only the size of "
                           "its held-out gain or end MAPE"
                         : " passed too") +
          "; with " + a.lead + (a.provisional ? " entered provisionally" : " entered") +
          " there the selection found " + names_of(a.found_other) + " (held-out cost " +
          fixed(a.cost_other, 3) + ") against " + names_of(a.found_first) + " (" +
          fixed(a.cost_first, 3) + "; its path errors the lower: p " +
          (a.p_value < 1e-4 ? std::string("< 1e-4") : fixed(a.p_value, 4)) + "): " +
          (a.taken     ? "this route is reported"
           : any_taken ? "another route is reported"
                       : "the first route is reported") +
          ".\n";
  }
  if (!r.alternative.empty()) md += "\n";
  for (const PairEntry& e : r.pairs) {
    md += "- Round " + std::to_string(e.round) + " found no cause and no lead alone; " + e.first +
          " with " + e.second + " together: delta BIC " + fixed(e.delta_bic, 1) +
          ", path error gain " + fixed(100.0 * e.gain, 1) + " %, p " +
          (e.p_value < 1e-4 ? std::string("< 1e-4") : fixed(e.p_value, 4)) + ", end MAPE " +
          (e.end_mape_improves ? "better" : "worse") + ": " +
          (e.significant ? "they pass together" : "not passing") + ".\n";
  }
  if (!r.pairs.empty()) md += "\n";
  std::string taken_lead;  // the lead of the other route reported, if any
  for (const AlternativeRoute& a : r.alternative) {
    if (a.taken) taken_lead = a.lead;
  }
  for (const std::string& p : r.provisional) {
    md +=
        "- " + p + " entered provisionally: " +
        (p == taken_lead ? std::string("the other route's lead")
                         : std::string("no candidate passed alone in its round")) +
        ", and the training windows supported it best (effects can mask each other until one "
        "is modelled); " +
        (std::find(r.found.begin(), r.found.end(), p) != r.found.end()
             ? "the causes found on top of it kept it"
             : "it was taken out again") +
        (std::isfinite(r.joint_p_value) ? " (the causes together against the model before it: p " +
                                              fixed(r.joint_p_value, 4) + ")"
                                        : std::string()) +
        ".\n";
  }
  if (!r.provisional.empty()) md += "\n";
  if (!r.backward.empty()) {
    md +=
        "Backward check (each cause against the others refitted without it, by the rule it "
        "entered by):\n\n"
        "| cause | against | path error gain % | delta BIC | p | needed? |\n"
        "|---|---|---|---|---|---|\n";
    for (const BackwardCheck& b : r.backward) {
      std::string others;
      for (const std::string& n : b.others) others += (others.empty() ? "" : ", ") + n;
      md += "| " + b.name + " | " + others + " | " + fixed(100.0 * b.gain, 1) + " | " +
            fixed(b.delta_bic, 1) + " | " +
            (b.p_value < 1e-4 ? std::string("< 1e-4") : fixed(b.p_value, 4)) + " | " +
            (b.kept ? "yes" : "no") + " |\n";
    }
    std::string dropped;
    for (const BackwardCheck& b : r.backward) {
      const bool kept = std::find(r.found.begin(), r.found.end(), b.name) != r.found.end();
      if (!kept && dropped.find(b.name) == std::string::npos) {
        dropped += (dropped.empty() ? "" : ", ") + b.name;
      }
    }
    md += dropped.empty()
              ? "\nEvery cause found is needed beside the others.\n\n"
              : "\nDropped (the one the data needed least, then the check again): " + dropped +
                    ".\n\n";
  }
  for (const Exchange& e : r.exchanges) {
    md += "- Exchange check: " + e.added + " in place of " + e.removed +
          " (both passed in the same round): held-out cost " + fixed(e.cost_before, 3) + " -> " +
          fixed(e.cost_after, 3) + ", " + (e.accepted ? "exchanged" : "kept " + e.removed) + ".\n";
  }
  if (!r.exchanges.empty()) md += "\n";
  if (!r.notes.empty()) {
    md += "Limits:\n\n";
    for (const std::string& n : r.notes) md += "- " + n + "\n";
    md += "\n";
  }
  md += "## What is left\n\n";
  if (r.corrections.empty()) {
    md += "Too few moving samples to test the residual for structure.\n\n";
  } else {
    md +=
        "The residual acceleration of the model with the causes above (measured minus model, "
        "along the radial direction from s and across it, " +
        std::to_string(r.n_acceleration_samples) +
        " samples where the object or the model moves; median " +
        fixed(r.median_residual_radial, 2) + " m/s^2 outward and " +
        fixed(r.median_residual_across, 2) +
        " m/s^2 across, taken out first) smoothed over each group of features, fitted on the "
        "training windows and scored on the held-out ones against that constant:\n\n"
        "| feature | bandwidth | cross-validated gain % | held-out gain % | p | RMS m/s^2 | "
        "largest |\n"
        "|---|---|---|---|---|---|---|\n";
    for (size_t i = 0; i < r.corrections.size(); ++i) {
      const ResidualCorrection& c = r.corrections[i];
      md += "| " + c.feature + (static_cast<int>(i) == r.chosen_correction ? " (chosen)" : "") +
            " | " + fixed(c.bandwidth, 2) + " " + c.unit + " | " + fixed(100.0 * c.cv_gain, 1) +
            " | " + fixed(100.0 * c.heldout_gain, 1) + " | " +
            (c.p_value < 1e-4 ? std::string("< 1e-4") : fixed(c.p_value, 4)) + " | " +
            fixed(c.heldout_rms_mps2, 2) + " | " + c.where + " |\n";
    }
    md += "\n";
    if (r.unexplained) {
      const ResidualCorrection& c = r.corrections[static_cast<size_t>(r.chosen_correction)];
      md += "**Unexplained**: the residual is structured by " + c.feature + " (" + c.where +
            "); the correction removes " + fixed(100.0 * c.heldout_gain, 1) +
            " % of the held-out residual. Something outside the catalogue is in the data "
            "(picture: residual_correction.png).\n\n";
    } else {
      md +=
          "No correction removes a significant part of the held-out residual: what is left "
          "looks like scatter.\n\n";
    }
  }
  md += "## What was added and what it gained\n\n";
  if (r.found.empty()) {
    md += "Nothing was added; extended_model.json is the nominal model.\n";
  } else {
    md += "extended_model.json adds the causes above. Held-out end-position MAPE: " +
          fixed(r.baseline_end_mape, 1) + " % -> " + fixed(r.extended_end_mape, 1) + " % (" +
          fixed(r.gain_pct, 1) + " % lower); held-out path error " +
          fixed(r.baseline_path_error, 3) + " -> " + fixed(r.extended_path_error, 3) + " scales.\n";
  }
  return md;
}

}  // namespace airtwin
