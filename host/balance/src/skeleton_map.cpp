// Built-in joint-name tables and a shape-based fallback.
//
// Names are compared after lower-casing and dropping the characters " _-.",
// and every joint is also tried without any prefix that ends at a ':' or at
// one of those separators: "mixamorig:LeftUpLeg", "Character1_LeftUpLeg",
// "Skeleton_LThigh", "Bip01 L Thigh" and "DEF-thigh.L" all offer their
// unprefixed spellings ("leftupleg", "lthigh", "thighl", ...).
//
// The table holds, per convention, the aliases of every bone ('|' between
// alternatives, the first that matches wins; '*' stands for the side token of
// the convention, e.g. "left"/"right" or "l"/"r"). The convention that finds
// the most bones wins; a signature (a word only that convention's files
// carry) breaks ties between conventions that share their names.
#include "tonus/host/balance/skeleton_map.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>
#include <sstream>

namespace tonus::balance {
namespace {

using sim::Bone;

bool is_separator(char c) { return c == ' ' || c == '_' || c == '-' || c == '.'; }

std::string normalise(std::string_view name) {
  const auto colon = name.rfind(':');
  if (colon != std::string_view::npos) name.remove_prefix(colon + 1);
  std::string out;
  for (const char c : name) {
    if (is_separator(c)) continue;
    out.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  }
  return out;
}

// The normalised name and its normalised unprefixed tails (after each
// separator), longest first.
std::vector<std::string> spellings(std::string_view name) {
  const auto colon = name.rfind(':');
  if (colon != std::string_view::npos) name.remove_prefix(colon + 1);
  std::vector<std::string> out{normalise(name)};
  for (std::size_t i = 0; i + 1 < name.size(); ++i) {
    if (is_separator(name[i]) && !is_separator(name[i + 1])) {
      std::string tail = normalise(name.substr(i + 1));
      if (!tail.empty() && std::find(out.begin(), out.end(), tail) == out.end()) out.push_back(std::move(tail));
    }
  }
  return out;
}

// Aliases of one convention, in Bone order, one-sided: the left and right
// limbs share an entry written with '*'.
struct Convention {
  std::string_view name;
  std::string_view left, right;  // the side tokens, lower case
  std::string_view signature;    // lower-case substring of some raw joint name that marks the convention, or ""
  std::string_view hips, spine, chest, neck, head;
  std::string_view shoulder, upper_arm, lower_arm, hand;
  std::string_view upper_leg, lower_leg, foot, toes;
};

// clang-format off
constexpr Convention kConventions[] = {
  // name                         sides          signature
  {"MotionBuilder HumanIK",       "left", "right", "",
   "hips", "spine", "spine1|spine2", "neck", "head",
   "*shoulder", "*arm", "*forearm", "*hand", "*upleg", "*leg", "*foot", "*toebase"},
  {"CMU (cgspeed BVH)",           "left", "right", "lhipjoint",
   "hips", "spine", "spine1", "neck", "head",
   "*shoulder", "*arm", "*forearm", "*hand", "*upleg", "*leg", "*foot", "*toebase"},
  {"Mixamo",                      "left", "right", "mixamorig",
   "hips", "spine", "spine1|spine2", "neck", "head",
   "*shoulder", "*arm", "*forearm", "*hand", "*upleg", "*leg", "*foot", "*toebase"},
  {"Perception Neuron",           "left", "right", "inhand",
   "hips", "spine", "spine2|spine1", "neck", "head",
   "*shoulder", "*arm", "*forearm", "*hand", "*upleg", "*leg", "*foot", "*toebase"},
  {"Rokoko",                      "left", "right", "",
   "hips", "spine", "spine2|spine1", "neck", "head",
   "*shoulder", "*arm", "*forearm", "*hand", "*thigh", "*shin", "*foot", "*toe"},
  {"Xsens MVN",                   "left", "right", "",
   "pelvis", "l5|l3", "t8|t12", "neck", "head",
   "*shoulder", "*upperarm", "*forearm", "*hand", "*upperleg", "*lowerleg", "*foot", "*toe"},
  {"Unity HumanBodyBones",        "left", "right", "",
   "hips", "spine", "chest|upperchest", "neck", "head",
   "*shoulder", "*upperarm", "*lowerarm", "*hand", "*upperleg", "*lowerleg", "*foot", "*toes"},
  {"VRM (J_Bip)",                 "l", "r", "",
   "jbipchips", "jbipcspine", "jbipcchest|jbipcupperchest", "jbipcneck", "jbipchead",
   "jbip*shoulder", "jbip*upperarm", "jbip*lowerarm", "jbip*hand",
   "jbip*upperleg", "jbip*lowerleg", "jbip*foot", "jbip*toebase"},
  {"Bandai Namco Research Motiondataset", "l", "r", "",
   "hips", "spine", "chest", "neck", "head",
   "shoulder*", "upperarm*", "lowerarm*", "hand*", "upperleg*", "lowerleg*", "foot*", "toes*"},
  {"Blender Rigify",              "l", "r", "",
   "spine", "spine001", "spine002|spine003", "spine004|spine005", "spine006|spine005",
   "shoulder*", "upperarm*", "forearm*", "hand*", "thigh*", "shin*", "foot*", "toe*"},
  {"3dsMax Biped",                "l", "r", "bip0",
   "pelvis", "spine", "spine1|spine2", "neck", "head",
   "*clavicle", "*upperarm", "*forearm", "*hand", "*thigh", "*calf", "*foot", "*toe0|*toe"},
  {"Daz",                         "l", "r", "",
   "hip", "abdomenlower|abdomen", "chestlower|chest|chestupper", "necklower|neck", "head",
   "*collar", "*shldrbend|*shldr", "*forearmbend|*forearm", "*hand",
   "*thighbend|*thigh", "*shin", "*foot", "*toe"},
  {"OptiTrack Motive",            "l", "r", "",
   "hip|hips", "ab", "chest", "neck", "head",
   "*shoulder", "*uarm", "*farm", "*hand", "*thigh", "*shin", "*foot", "*toe"},
};
// clang-format on

// The aliases of bone b in convention c, with the side token put in.
std::vector<std::string> aliases(const Convention& c, Bone b) {
  const sim::BoneInfo& info = sim::info(b);
  std::string_view pattern;
  switch (b) {
    case Bone::Hips: pattern = c.hips; break;
    case Bone::Spine: pattern = c.spine; break;
    case Bone::Chest: pattern = c.chest; break;
    case Bone::Neck: pattern = c.neck; break;
    case Bone::Head: pattern = c.head; break;
    case Bone::LeftShoulder:
    case Bone::RightShoulder: pattern = c.shoulder; break;
    case Bone::LeftUpperArm:
    case Bone::RightUpperArm: pattern = c.upper_arm; break;
    case Bone::LeftLowerArm:
    case Bone::RightLowerArm: pattern = c.lower_arm; break;
    case Bone::LeftHand:
    case Bone::RightHand: pattern = c.hand; break;
    case Bone::LeftUpperLeg:
    case Bone::RightUpperLeg: pattern = c.upper_leg; break;
    case Bone::LeftLowerLeg:
    case Bone::RightLowerLeg: pattern = c.lower_leg; break;
    case Bone::LeftFoot:
    case Bone::RightFoot: pattern = c.foot; break;
    case Bone::LeftToes:
    case Bone::RightToes: pattern = c.toes; break;
  }
  const std::string_view side = info.side == sim::Side::right ? c.right : c.left;
  std::vector<std::string> out;
  while (!pattern.empty()) {
    const auto bar = pattern.find('|');
    const std::string_view one = pattern.substr(0, bar);
    std::string alias;
    for (const char ch : one) {
      if (ch == '*')
        alias += side;
      else
        alias.push_back(ch);
    }
    if (!alias.empty()) out.push_back(std::move(alias));
    if (bar == std::string_view::npos) break;
    pattern.remove_prefix(bar + 1);
  }
  return out;
}

struct Names {
  std::vector<std::vector<std::string>> spelled;  // per joint; empty for End Sites
  std::vector<std::string> raw_lower;
};

Names names_of(const motion::Clip& clip) {
  Names n;
  for (const motion::Joint& j : clip.joints) {
    n.spelled.push_back(j.end_site ? std::vector<std::string>{} : spellings(j.name));
    std::string lower;
    for (const char c : j.name) lower.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    n.raw_lower.push_back(std::move(lower));
  }
  return n;
}

int find_alias(const Names& n, const std::vector<std::string>& alias_list) {
  for (const std::string& a : alias_list) {
    for (std::size_t j = 0; j < n.spelled.size(); ++j) {
      const auto& s = n.spelled[j];
      if (std::find(s.begin(), s.end(), a) != s.end()) return static_cast<int>(j);
    }
  }
  return -1;
}

// Exact joint name (normalised, End Sites excluded), for mapping files.
int find(const motion::Clip& clip, std::string_view name) {
  if (name.empty()) return -1;
  const std::string want = normalise(name);
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    if (!clip.joints[j].end_site && normalise(clip.joints[j].name) == want) return static_cast<int>(j);
  }
  return -1;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0) s.remove_suffix(1);
  return s;
}

constexpr Bone kRequired[] = {Bone::Hips,          Bone::LeftUpperArm,  Bone::LeftLowerArm,  Bone::LeftHand,
                              Bone::RightUpperArm, Bone::RightLowerArm, Bone::RightHand,     Bone::LeftUpperLeg,
                              Bone::LeftLowerLeg,  Bone::LeftFoot,      Bone::RightUpperLeg, Bone::RightLowerLeg,
                              Bone::RightFoot};

// ---- The shape-based fallback -------------------------------------------
// Rest pose in the file's axes (Y up; a character facing +Z has its left
// side at +X, as in every convention above).

struct Rest {
  std::vector<Eigen::Vector3d> p;
  std::vector<int> parent;
  std::vector<bool> leaf;
};

Rest rest_of(const motion::Clip& clip) {
  Rest r;
  const std::size_t n = clip.joints.size();
  r.p.resize(n);
  r.parent.resize(n);
  r.leaf.assign(n, true);
  for (std::size_t j = 0; j < n; ++j) {
    const int par = clip.joints[j].parent;
    r.parent[j] = par;
    r.p[j] = clip.joints[j].offset;
    if (par >= 0) {
      r.p[j] += r.p[static_cast<std::size_t>(par)];
      r.leaf[static_cast<std::size_t>(par)] = false;
    }
  }
  return r;
}

std::vector<int> path_from_root(const Rest& r, int j) {
  std::vector<int> path;
  for (; j >= 0; j = r.parent[static_cast<std::size_t>(j)]) path.push_back(j);
  std::reverse(path.begin(), path.end());
  return path;
}

int common_ancestor(const Rest& r, int a, int b) {
  const std::vector<int> pa = path_from_root(r, a), pb = path_from_root(r, b);
  int lca = -1;
  for (std::size_t i = 0; i < std::min(pa.size(), pb.size()) && pa[i] == pb[i]; ++i) lca = pa[i];
  return lca;
}

// The joints strictly below `top` down to `leaf`, End Sites left out.
std::vector<int> chain(const motion::Clip& clip, const Rest& r, int top, int leaf) {
  std::vector<int> out;
  bool below = false;
  for (const int j : path_from_root(r, leaf)) {
    if (below && !clip.joints[static_cast<std::size_t>(j)].end_site) out.push_back(j);
    if (j == top) below = true;
  }
  return out;
}

// A limb chain [girdle?, upper, lower, end, extremities...]: the last two
// long segments (at least `long_m`) that follow each other are upper-to-lower
// and lower-to-end (the last, so that a long clavicle is not taken for the
// upper arm). Returns {girdle or -1, upper, lower, end, after end or -1}.
std::optional<std::array<int, 5>> limb(const Rest& r, const std::vector<int>& c, double long_m) {
  std::optional<std::array<int, 5>> found;
  for (std::size_t i = 1; i + 1 < c.size(); ++i) {
    const auto at = [&](std::size_t k) { return r.p[static_cast<std::size_t>(c[k])]; };
    if ((at(i) - at(i - 1)).norm() >= long_m && (at(i + 1) - at(i)).norm() >= long_m) {
      found = std::array<int, 5>{i >= 2 ? c[i - 2] : -1, c[i - 1], c[i], c[i + 1], i + 2 < c.size() ? c[i + 2] : -1};
    }
  }
  return found;
}

// The bones from the skeleton's shape, or why not.
std::optional<std::array<int, sim::kBoneCount>> by_topology(const motion::Clip& clip, std::string& why) {
  const Rest r = rest_of(clip);
  std::vector<int> leaves;
  double lo = 0.0, hi = 0.0;
  for (std::size_t j = 0; j < r.p.size(); ++j) {
    if (j == 0 || r.p[j].y() < lo) lo = r.p[j].y();
    if (j == 0 || r.p[j].y() > hi) hi = r.p[j].y();
    if (r.leaf[j]) leaves.push_back(static_cast<int>(j));
  }
  const double height = hi - lo;
  if (leaves.size() < 5 || !(height > 0.0)) {
    why = "it has " + std::to_string(leaves.size()) + " ends, a humanoid has at least 5 (feet, hands, head)";
    return std::nullopt;
  }
  const auto y = [&](int j) { return r.p[static_cast<std::size_t>(j)].y(); };
  const auto x = [&](int j) { return r.p[static_cast<std::size_t>(j)].x(); };
  std::vector<int> by_height = leaves;
  std::stable_sort(by_height.begin(), by_height.end(), [&](int a, int b) { return y(a) < y(b); });
  // Legs: the lowest end, and the lowest one on the other side of where their chains part.
  const int foot_a = by_height.front();
  int foot_b = -1, hips = -1;
  for (std::size_t i = 1; i < by_height.size() && y(by_height[i]) < lo + 0.25 * height; ++i) {
    const int lca = common_ancestor(r, foot_a, by_height[i]);
    if (lca >= 0 && (x(foot_a) - x(lca)) * (x(by_height[i]) - x(lca)) < 0.0) {
      foot_b = by_height[i];
      hips = lca;
      break;
    }
  }
  if (foot_b < 0) {
    why = "no two ends near the ground on either side (feet)";
    return std::nullopt;
  }
  const int left_foot = x(foot_a) > x(foot_b) ? foot_a : foot_b, right_foot = left_foot == foot_a ? foot_b : foot_a;
  const int head_end = by_height.back();
  // Arms: the ends farthest to either side, above the hips, outside the legs.
  const auto in_leg = [&](int j) {
    const int a = common_ancestor(r, j, foot_a), b = common_ancestor(r, j, foot_b);
    return a != hips || b != hips;
  };
  int left_hand = -1, right_hand = -1;
  for (const int j : leaves) {
    if (j == head_end || y(j) < y(hips) + 0.15 * height || in_leg(j)) continue;
    if (left_hand < 0 || x(j) > x(left_hand)) left_hand = j;
    if (right_hand < 0 || x(j) < x(right_hand)) right_hand = j;
  }
  if (left_hand < 0 || left_hand == right_hand || x(left_hand) - x(hips) < 0.15 * height ||
      x(hips) - x(right_hand) < 0.15 * height) {
    why = "no ends stretched out to either side above the hips (arms in a T-pose)";
    return std::nullopt;
  }
  std::array<int, sim::kBoneCount> m{};
  m.fill(-1);
  const auto set = [&](Bone b, int j) { m[sim::index(b)] = j; };
  set(Bone::Hips, hips);
  const double long_leg = 0.15 * height, long_arm = 0.1 * height;
  for (int side = 0; side < 2; ++side) {
    const int foot_end = side == 0 ? left_foot : right_foot;
    const auto leg = limb(r, chain(clip, r, hips, foot_end), long_leg);
    const int hand_end = side == 0 ? left_hand : right_hand;
    const int branch = common_ancestor(r, hand_end, head_end);
    const auto arm = limb(r, chain(clip, r, branch, hand_end), long_arm);
    if (!leg || !arm) {
      why = std::string("the ") + (side == 0 ? "left " : "right ") + (leg ? "arm" : "leg") +
            " has no two long segments in a row (upper and lower limb)";
      return std::nullopt;
    }
    const auto& l = *leg;
    const auto& a = *arm;
    set(side == 0 ? Bone::LeftUpperLeg : Bone::RightUpperLeg, l[1]);
    set(side == 0 ? Bone::LeftLowerLeg : Bone::RightLowerLeg, l[2]);
    set(side == 0 ? Bone::LeftFoot : Bone::RightFoot, l[3]);
    set(side == 0 ? Bone::LeftToes : Bone::RightToes, l[4]);
    set(side == 0 ? Bone::LeftShoulder : Bone::RightShoulder, a[0]);
    set(side == 0 ? Bone::LeftUpperArm : Bone::RightUpperArm, a[1]);
    set(side == 0 ? Bone::LeftLowerArm : Bone::RightLowerArm, a[2]);
    set(side == 0 ? Bone::LeftHand : Bone::RightHand, a[3]);
  }
  // Spine: hips to the highest end; the chest is where the arms branch off.
  const std::vector<int> spine = chain(clip, r, hips, head_end);
  if (spine.empty()) {
    why = "nothing between the hips and the highest end (head)";
    return std::nullopt;
  }
  const int arms = common_ancestor(r, left_hand, right_hand);
  const auto chest_at = std::find(spine.begin(), spine.end(), arms);
  set(Bone::Head, spine.back());
  if (chest_at != spine.end() && *chest_at != spine.back()) {
    set(Bone::Chest, *chest_at);
    if (chest_at != spine.begin()) set(Bone::Spine, spine.front());
    if (chest_at + 1 < spine.end() - 1) set(Bone::Neck, *(spine.end() - 2));
  }
  return m;
}

}  // namespace

MapResult map_skeleton(const motion::Clip& clip, std::string_view override_text) {
  MapResult r;
  const Names names = names_of(clip);
  // The convention that finds the most bones; its signature breaks ties.
  int best_score = -1;
  for (const Convention& conv : kConventions) {
    std::array<int, sim::kBoneCount> joints{};
    int found = 0;
    for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
      joints[b] = find_alias(names, aliases(conv, sim::kBones[b].bone));
      found += joints[b] >= 0 ? 1 : 0;
    }
    bool signed_by = false;
    if (!conv.signature.empty()) {
      for (const std::string& n : names.raw_lower) signed_by = signed_by || n.find(conv.signature) != std::string::npos;
    }
    const int score = 2 * found + (signed_by ? 1 : 0);
    if (score > best_score) {
      best_score = score;
      r.map.convention = std::string(conv.name);
      r.map.joint = joints;
    }
  }
  // Too few names known: try the skeleton's shape.
  int required_found = 0;
  for (const Bone b : kRequired) required_found += r.map.joint[sim::index(b)] >= 0 ? 1 : 0;
  std::string shape_problem;
  if (2 * required_found < static_cast<int>(std::size(kRequired))) {
    if (const auto shape = by_topology(clip, shape_problem)) {
      r.notes.push_back("no known joint-name convention (best: " + r.map.convention + ", " +
                        std::to_string(required_found) +
                        " required bones); bones chosen by topology: legs to the lowest ends, arms to the ends "
                        "farthest to the sides, the head to the highest end");
      r.map.convention = "topology";
      r.map.joint = *shape;
      shape_problem.clear();
    }
  }

  // Overrides: "Bone = JointName" per line.
  std::istringstream lines{std::string(override_text)};
  std::string line;
  int line_no = 0;
  bool overridden = false;
  while (std::getline(lines, line)) {
    ++line_no;
    std::string_view l = line;
    if (const auto hash = l.find('#'); hash != std::string_view::npos) l = l.substr(0, hash);
    l = trim(l);
    if (l.empty()) continue;
    const auto eq = l.find('=');
    const auto where = "mapping line " + std::to_string(line_no) + ": ";
    if (eq == std::string_view::npos) {
      r.error = where + "expected 'Bone = JointName', found '" + std::string(l) + "'";
      return r;
    }
    const std::string_view bone_name = trim(l.substr(0, eq)), joint_name = trim(l.substr(eq + 1));
    const auto bone = sim::bone_from_name(bone_name);
    if (!bone) {
      r.error = where + "'" + std::string(bone_name) + "' is not a HumanBodyBones name (e.g. LeftUpperLeg)";
      return r;
    }
    const int j = find(clip, joint_name);
    if (j < 0) {
      r.error = where + "the skeleton has no joint named '" + std::string(joint_name) + "'";
      return r;
    }
    r.map.joint[sim::index(*bone)] = j;
    overridden = true;
  }
  if (overridden) r.map.convention += " + custom";

  const std::string shape_note =
      shape_problem.empty() ? std::string() : "; the skeleton's shape did not help either: " + shape_problem;
  for (const Bone b : kRequired) {
    if (r.map.joint[sim::index(b)] < 0) {
      r.error = "the skeleton has no joint for " + std::string(sim::name(b)) + " (best match: " + r.map.convention +
                ")" + shape_note + "; map it with a mapping file line '" + std::string(sim::name(b)) +
                " = <joint name>'";
      return r;
    }
  }
  if (r.map.joint[sim::index(Bone::Neck)] < 0 && r.map.joint[sim::index(Bone::Head)] < 0) {
    r.error = "the skeleton has neither a Neck nor a Head joint";
    return r;
  }
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
    if (r.map.joint[b] < 0) r.notes.push_back("no joint for " + std::string(sim::kBones[b].name) + ": synthesised");
  }
  return r;
}

}  // namespace tonus::balance
