// SPDX-License-Identifier: Apache-2.0
#include "claims.h"

#include "fusedet/boost/paired_comparison.h"
#include "text.h"

namespace fusedet::tools::experiments {
Measured measure(const std::vector<boosting::FrameOutcome>& frames, const boosting::BootstrapConfig& b) {
  std::vector<std::size_t> all(frames.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  Measured m;
  m.f.value = boosting::fMeasureOf(frames, all);
  m.ap.value = boosting::averagePrecisionOf(frames, all);
  m.f.interval = boosting::bootstrapInterval(
      frames.size(), [&](const std::vector<std::size_t>& idx) { return boosting::fMeasureOf(frames, idx); }, b);
  m.ap.interval = boosting::bootstrapInterval(
      frames.size(), [&](const std::vector<std::size_t>& idx) { return boosting::averagePrecisionOf(frames, idx); }, b);
  return m;
}

Claim compare(const std::string& cls, const std::string& key, const std::string& text, const std::string& lhs,
              const std::vector<boosting::FrameOutcome>& a, const std::string& rhs,
              const std::vector<boosting::FrameOutcome>& b, const boosting::BootstrapConfig& boot) {
  const boosting::PairedComparison p = boosting::comparePaired(a, b, boot);
  Claim c;
  c.className = cls;
  c.key = key;
  c.text = text;
  c.lhs = lhs;
  c.rhs = rhs;
  c.fDifference = {p.f.difference, p.f.interval};
  c.apDifference = {p.ap.difference, p.ap.interval};
  c.verdict = p.f.verdict;
  c.apVerdict = p.ap.verdict;
  return c;
}

void judgeClaims(ExperimentReport& report, const std::string& cls,
                 std::map<std::string, std::vector<boosting::FrameOutcome>>& fr, const boosting::BootstrapConfig& boot) {
  const auto claim = [&](const std::string& key, const std::string& text, const std::string& a,
                         const std::string& b) {
    if (fr.count(a) && fr.count(b)) report.claims.push_back(compare(cls, key, text, a, fr[a], b, fr[b], boot));
  };
  claim("joint_gt_laser", "joint pool (all layers) > laser only", "all", "laser");
  claim("joint_gt_camera", "joint pool (all layers) > camera only", "all", "camera");
  claim("joint_gt_and", "joint pool (all layers) > laser AND camera", "all", "and");
  claim("four_gt_and", "joint pool (4 layers) > laser AND camera", "four", "and");
  claim("corners_help", "corner features help (all > all without corners)", "all", "no_corners");
  if (cls == "person") claim("joint_gt_hog", "joint pool (all layers) > OpenCV HOG", "all", "hog");
}

void setGoals(ExperimentReport& report) {
  const std::map<std::string, double> targets = {{"car", 0.8}, {"bike", 0.6}, {"person", 0.5}};
  for (const ConfigResult& all : report.results) {
    if (all.config != "all" || !targets.count(all.className)) continue;
    report.goals.push_back({all.className, "F >= " + shortNum(targets.at(all.className)), targets.at(all.className),
                            all.f});
    if (all.className == "person")
      for (const ConfigResult& r : report.results)
        if (r.className == "person" && r.config == "hog" && r.f.value)
          report.goals.push_back(
              {"person", "F >= 2 x HOG's F (" + boosting::formatMeasure(r.f.value) + ")", 2 * *r.f.value, all.f});
  }
}

}  // namespace fusedet::tools::experiments
