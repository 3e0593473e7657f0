// A mapping from a file's own marker labels (see the header for the rules and why).
#include "kin2grf/io/marker_labels.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <map>
#include <optional>
#include <utility>

namespace kin2grf {

namespace {

/// The vocabulary: spellings (lower case, separators removed) of each landmark in the marker sets
/// gait labs use: Plug-in Gait and Helen Hayes (RKNE, RANK, RHEE, RTOE, RMED), ISB and CAST
/// (LE/ME or FLE/FME, LM/MM or FAL/TAM, FCC or CA, FM1/FM5, IAS/IPS), OpenSim's and OpenCap's
/// (R.Knee.Lat, r_mknee, r_5meta, r_calc), Visual3D's (RLKN, RMKN) and spelt-out ones; and those of
/// the sets sports and treadmill labs use: Qualisys's and OptiTrack Motive's animation sets
/// (WaistLFront, LKneeOut, LAnkleOut, LHeelBack, LForefootIn/Out, LToeIn/Out, LToeTip,
/// LShoulderTop), Vicon's production set (LFWT, LBWT), the conventional gait model 2.4's
/// forefoot (LFMH, LSMH, LVMH), the Oxford foot model's (LD1M, LD5M, LHLX), Motek's Human Body
/// Model for GRAIL and CAREN treadmills (LLEK, LLM, LMT5, LLEE, LLW), the RRIS40 set (RFMT1) and
/// IOR-gait's forefoot (RFM, RSM, RVM: the 1st, 2nd and 5th metatarsal heads, Leardini et al. 2007).
struct Word {
  const char* key;
  std::vector<const char*> spellings;
};
const std::vector<Word>& vocabulary() {
  static const std::vector<Word> v = {
      {"asis", {"asi", "asis", "ias", "antsupiliacspine", "anteriorsuperioriliacspine", "waistfront", "fwt"}},
      {"psis", {"psi", "psis", "ips", "postsupiliacspine", "posteriorsuperioriliacspine", "waistback", "bwt"}},
      {"sacrum", {"sacr", "sacrum", "sac", "sacral", "vsacral"}},
      {"hjc", {"hjc", "hipjc", "hipjointcentre", "hipjointcenter", "hipcentre", "hipcenter"}},
      {"kjc", {"kjc", "kneejc", "kneejointcentre", "kneejointcenter", "kneecentre", "kneecenter"}},
      {"ajc", {"ajc", "anklejc", "anklejointcentre", "anklejointcenter", "anklecentre", "anklecenter"}},
      {"knee_lateral", {"kne", "knee", "kneelat", "kneelateral", "latknee", "lateralknee", "lkn", "le", "fle", "lfe", "lfc", "lep",
                        "lepi", "latepi", "latepicondyle", "lateralepicondyle", "lfepi", "femlatepi", "kneeout", "lek"}},
      {"knee_medial", {"knm", "kneemed", "kneemedial", "medknee", "medialknee", "mknee", "mkn", "me", "fme", "mfe", "mfc", "mep", "mepi",
                       "medepi", "medepicondyle", "medialepicondyle", "mfepi", "femmedepi", "kneein", "mek"}},
      {"ankle_lateral", {"ank", "ankle", "anklelat", "anklelateral", "latankle", "lateralankle", "lm", "lma", "lmal", "lmall", "latmal",
                         "latmalleolus", "lateralmalleolus", "latmall", "fal", "ankleout"}},
      {"ankle_medial", {"ankm", "ankmed", "anklemed", "anklemedial", "medankle", "medialankle", "mankle", "mm", "mma", "mmal", "mmall",
                        "medmal", "medmalleolus", "medialmalleolus", "medmall", "tam", "med", "anklein"}},
      {"heel", {"hee", "heel", "hel", "cal", "calc", "calcaneus", "fcc", "ca", "heelbottom", "heelback", "heelpost", "phe"}},
      {"mt1", {"mt1", "mth1", "mh1", "fm1", "met1", "meta1", "1mt", "1meta", "1stmet", "mt1head", "toemed", "toemedial", "mtp1", "1mtp", "fm", "fmt1", "fmh", "d1m", "1st", "forefootin", "forefoot1", "toein"}},
      {"mt2", {"mt2", "mth2", "mh2", "fm2", "met2", "meta2", "2mt", "2meta", "2ndmet", "mtp2", "sm", "fmt2", "smh", "2nd", "forefoot2"}},
      {"mt5", {"mt5", "mth5", "mh5", "fm5", "met5", "meta5", "5mt", "5meta", "5thmet", "mt5head", "toelat", "toelateral", "mtp5", "5mtp", "vm", "fmt5", "vmh", "d5m", "5th", "forefootout", "forefoot5", "toeout"}},
      {"toe", {"toe"}},
      {"hallux", {"hlx", "hallux", "hal", "toetip", "tiptoe", "bigtoe"}},
      {"shoulder", {"sho", "shoulder", "acr", "acromion", "acromium", "ac", "sae", "shouldertop"}},
      {"c7", {"c7", "cv7"}},
      {"clav", {"clav", "ij", "sjn", "clavicle", "jugularnotch", "manubrium"}},
      {"elbow", {"elb", "elbow", "elbowlat", "el", "lel", "hle", "elbowout", "lee"}},
      {"wrist", {"wra", "wrb", "wrist", "wri", "rs", "us", "rsp", "usp", "wristlat", "wristmed", "wristout", "wristin", "lw", "mw"}},
      {"head", {"fhd", "bhd", "head", "hea", "headfront", "headback", "headtop", "tophead", "headside"}},
  };
  return v;
}

/// Landmarks on the midline: a label with their word and no side prefix is read as one of them
/// (C7, CLAV and SACR are not a side letter and a word).
bool midline(const std::string& key) { return key == "sacrum" || key == "c7" || key == "clav"; }

std::string lower_alnum(const std::string& s) {
  std::string out;
  for (const unsigned char c : s)
    if (std::isalnum(c)) out += static_cast<char>(std::tolower(c));
  return out;
}

/// `word` is `stem` followed by one or more digits (RTH1's "th1", RTB3's "tb3").
bool numbered(const std::string& word, const std::string& stem) {
  return word.size() > stem.size() && word.compare(0, stem.size(), stem) == 0 &&
         std::all_of(word.begin() + static_cast<std::ptrdiff_t>(stem.size()), word.end(), [](unsigned char c) { return std::isdigit(c); });
}
bool starts_with(const std::string& word, const std::string& stem) { return word.size() > stem.size() && word.compare(0, stem.size(), stem) == 0; }

std::string lookup(const std::string& word) {
  if (word.empty()) return {};
  for (const auto& w : vocabulary())
    for (const char* s : w.spellings)
      if (word == s) return w.key;
  // Technical clusters: numbered (RTH1-3, RTB1-3, RSK1-4) or named by place on the segment
  // (R.Thigh.Upper, R.Shank.Top.Lateral). A single wand (RTHI, RTIB) is not a cluster.
  if (numbered(word, "th") || numbered(word, "thi") || starts_with(word, "thigh")) return "thigh_cluster";
  if (numbered(word, "tb") || numbered(word, "tib") || numbered(word, "sk") || starts_with(word, "shank") || starts_with(word, "shin"))
    return "shank_cluster";
  return {};
}

char side_word(const std::string& token) {
  const std::string t = lower_alnum(token);
  if (t == "r" || t == "right") return 'r';
  if (t == "l" || t == "left") return 'l';
  return 0;
}

}  // namespace

MarkerLabel read_marker_label(const std::string& label) {
  MarkerLabel out;
  if (label.find('#') != std::string::npos) return out;  // a repeated label's k-th occurrence: a preset's business
  // A byte outside ASCII (an accented letter, a byte the file mangled) is not dropped to make a
  // word: the label is left out.
  if (std::any_of(label.begin(), label.end(), [](char c) { return static_cast<unsigned char>(c) >= 0x80; })) return out;
  std::vector<std::string> tokens;
  std::string cur;
  for (const char c : label) {
    if (c == '.' || c == '_' || c == '-' || c == ' ' || c == ':') {
      if (!cur.empty()) tokens.push_back(cur), cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) tokens.push_back(cur);
  if (tokens.empty()) return out;
  // "R_FLE", "r.knee", "Right Knee": a side word first; "ASIS_R", "knee.left": last.
  if (tokens.size() >= 2) {
    std::string rest;
    if (const char s = side_word(tokens.front())) {
      for (std::size_t i = 1; i < tokens.size(); ++i) rest += tokens[i];
      if (const std::string k = lookup(lower_alnum(rest)); !k.empty()) return {s, k};
    }
    rest.clear();
    if (const char s = side_word(tokens.back())) {
      for (std::size_t i = 0; i + 1 < tokens.size(); ++i) rest += tokens[i];
      if (const std::string k = lookup(lower_alnum(rest)); !k.empty()) return {s, k};
    }
  }
  // One word: "C7" and "SACR" as they are; "RKNE", "LFLE", "RightKnee": a side prefix and a word.
  const std::string word = lower_alnum(label);
  if (const std::string k = lookup(word); !k.empty() && midline(k)) return {0, k};
  for (const auto& [prefix, s] : std::array<std::pair<const char*, char>, 4>{{{"right", 'r'}, {"left", 'l'}, {"r", 'r'}, {"l", 'l'}}}) {
    const std::string p = prefix;
    if (word.size() > p.size() + 1 && word.compare(0, p.size(), p) == 0)
      if (const std::string k = lookup(word.substr(p.size())); !k.empty() && !midline(k)) return {s, k};
  }
  // The side inside the word: Qualisys's and OptiTrack's pelvis markers ("WaistLFront", "WaistRBack").
  if (word.size() > 6 && word.compare(0, 5, "waist") == 0 && (word[5] == 'l' || word[5] == 'r'))
    if (const std::string k = lookup("waist" + word.substr(6)); !k.empty()) return {word[5], k};
  // A known word with no side ("Heel" is not "Hee" on the left), then "ASISR", "KneeL": a side
  // letter last, on a word of three letters or more.
  if (const std::string k = lookup(word); !k.empty()) return {0, k};
  if (word.size() >= 4 && (word.back() == 'r' || word.back() == 'l'))
    if (const std::string k = lookup(word.substr(0, word.size() - 1)); !k.empty() && !midline(k)) return {word.back(), k};
  return out;
}

namespace {

/// The labels found for each (side, landmark word), with the frames each holds data in.
struct Found {
  std::map<std::pair<char, std::string>, std::vector<std::pair<std::string, long>>> by_place;
  /// Labels that read as a landmark but were left out for holding too few samples, with their count.
  std::vector<std::string> too_few;

  /// The label for a place: the one holding data in the most frames; `notes` says when there were several.
  [[nodiscard]] std::string one(char side, const std::string& key, std::vector<std::string>& notes) const {
    const auto it = by_place.find({side, key});
    if (it == by_place.end()) return {};
    const auto& v = it->second;
    const auto best = std::max_element(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    if (v.size() > 1) {
      std::string others;
      for (const auto& [name, n] : v)
        if (name != best->first) others += (others.empty() ? "" : ", ") + name;
      notes.push_back(key + (side ? std::string(" (") + side + ")" : std::string()) + ": " + best->first + " taken (most frames) over " + others);
    }
    return best->first;
  }
  /// Every label for a place (the wrist's two markers, the head's four).
  [[nodiscard]] std::vector<std::string> all(char side, const std::string& key) const {
    std::vector<std::string> out;
    if (const auto it = by_place.find({side, key}); it != by_place.end())
      for (const auto& [name, n] : it->second) out.push_back(name);
    return out;
  }
};

std::string spellings_of(const std::string& key) {
  for (const auto& w : vocabulary())
    if (key == w.key) {
      std::string out;
      for (std::size_t i = 0; i < w.spellings.size() && i < 6; ++i) out += (i ? ", " : "") + std::string(w.spellings[i]);
      return out + (w.spellings.size() > 6 ? ", ..." : "");
    }
  return {};
}

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

/// Every label of `m` that reads as a landmark and holds data.
Found find_labels(const MarkerTrajectories& m) {
  Found f;
  std::vector<long> held(m.names.size(), 0);
  for (std::size_t i = 0; i < m.names.size(); ++i)
    for (Eigen::Index k = 0; k < m.frames(); ++k) held[i] += m.positions_m[i].row(k).allFinite();
  // An overground walk leaves the cameras' volume, and a file's modelled joint centres may hold
  // only the frames the model ran on (walking2: 414 of its best marker's 1002), so "holds data" is
  // a fifth of the best-seen marker's frames: what it leaves out is an empty label (a lower-body
  // capture's trunk labels) or a few frames of a ghost.
  const long most = held.empty() ? 0 : *std::max_element(held.begin(), held.end());
  for (std::size_t i = 0; i < m.names.size(); ++i) {
    const MarkerLabel l = read_marker_label(m.names[i]);
    if (l.landmark.empty()) continue;
    if (held[i] == 0 || 5 * held[i] < most) {
      f.too_few.push_back(m.names[i] + " (" + std::to_string(held[i]) + " of " + std::to_string(m.frames()) + " frames)");
      continue;
    }
    f.by_place[{l.side, l.landmark}].emplace_back(m.names[i], held[i]);
  }
  return f;
}

}  // namespace

LabelMapping map_marker_labels(const MarkerTrajectories& m, const MarkerTrajectories* static_markers) {
  LabelMapping out;
  const Found f = find_labels(m);
  out.too_few = f.too_few;
  const std::optional<Found> fs = static_markers ? std::optional<Found>(find_labels(*static_markers)) : std::nullopt;
  nlohmann::json lm = nlohmann::json::object();
  auto& notes = out.notes;
  const auto rule = [&](const std::string& landmark, nlohmann::json r, const std::string& said) {
    lm[landmark] = std::move(r);
    out.rules.push_back(landmark + " = " + said);
  };
  const auto missing = [&](const std::string& landmark, const std::string& what) { out.missing.push_back(landmark + ": " + what); };

  // The pelvis: both ASIS, and both PSIS or the sacrum.
  nlohmann::json pelvis;
  std::string pelvis_said;
  const std::string rasis = f.one('r', "asis", notes), lasis = f.one('l', "asis", notes);
  const std::string rpsis = f.one('r', "psis", notes), lpsis = f.one('l', "psis", notes), sacrum = f.one(0, "sacrum", notes);
  if (!rasis.empty() && !lasis.empty()) {
    if (!rpsis.empty() && !lpsis.empty()) {
      pelvis = {{"rasis", rasis}, {"lasis", lasis}, {"rpsis", rpsis}, {"lpsis", lpsis}};
      pelvis_said = rasis + ", " + lasis + ", " + rpsis + ", " + lpsis;
    } else if (!sacrum.empty()) {
      pelvis = {{"rasis", rasis}, {"lasis", lasis}, {"sacrum", sacrum}};
      pelvis_said = rasis + ", " + lasis + ", " + sacrum;
    }
    // An animation set's waist markers sit near the ASIS and PSIS, not on them: the hip centre is
    // then as good as their placement, which the user should know.
    const auto waist = [](const std::string& l) {
      const std::string w = lower_alnum(l);
      return w.find("waist") != std::string::npos || w.find("fwt") != std::string::npos || w.find("bwt") != std::string::npos;
    };
    if (!pelvis_said.empty() && (waist(rasis) || waist(lasis) || waist(rpsis) || waist(lpsis)))
      pelvis_said += " (waist markers taken as the ASIS and PSIS)";
  }
  const std::string rhjc = f.one('r', "hjc", notes), lhjc = f.one('l', "hjc", notes);
  if (!rhjc.empty() && !lhjc.empty()) rule("hip", {{"mean", {rhjc, lhjc}}}, "mean of the hip joint centres " + rhjc + ", " + lhjc);
  else if (!pelvis.is_null()) rule("hip", {{"harrington", pelvis}}, "Harrington et al. 2007 from " + pelvis_said);
  else missing("hip", "no hip joint centres (" + spellings_of("hjc") + ") and no pelvis: both ASIS (" + spellings_of("asis") +
                          ") with both PSIS (" + spellings_of("psis") + ") or a sacrum (" + spellings_of("sacrum") + ")");

  for (const char side : {'r', 'l'}) {
    const std::string s(1, side);
    // The foot's markers (also the distal segment of a functional ankle).
    const std::string heel = f.one(side, "heel", notes), mt1 = f.one(side, "mt1", notes), mt2 = f.one(side, "mt2", notes),
                      mt5 = f.one(side, "mt5", notes), toe = f.one(side, "toe", notes), hallux = f.one(side, "hallux", notes);
    std::vector<std::string> foot;
    for (const auto* x : {&heel, &mt1, &mt2, &mt5, &toe, &hallux})
      if (!x->empty()) foot.push_back(*x);
    // Knee and ankle: the joint centre, else the mean of the lateral and medial markers, else the
    // lateral one, else the static trial's carried by a cluster, else a functional centre.
    for (const auto& [joint, centre] : std::array<std::pair<const char*, const char*>, 2>{{{"knee", "kjc"}, {"ankle", "ajc"}}}) {
      const std::string name = std::string(joint) + "_" + s, lateral = std::string(joint) + "_lateral", medial = std::string(joint) + "_medial";
      const std::string jc = f.one(side, centre, notes), lat = f.one(side, lateral, notes), med = f.one(side, medial, notes);
      const bool knee = std::string(joint) == "knee";
      // The segment above the joint carries a static trial's markers (the knee's epicondyles on
      // the thigh, the malleoli on the shank); for a functional centre, the segment below moves
      // against it.
      std::vector<std::string> carrier = f.all(side, knee ? "thigh_cluster" : "shank_cluster");
      std::vector<std::string> below = knee ? f.all(side, "shank_cluster") : foot;
      std::sort(carrier.begin(), carrier.end());  // for the reader: the fit does not depend on the order
      if (knee) std::sort(below.begin(), below.end());
      std::string slat, smed;
      bool carried = carrier.size() >= 3 && static_markers;
      if (carried) {
        slat = fs->one(side, lateral, notes), smed = fs->one(side, medial, notes);
        for (const auto& c : carrier) carried = carried && static_markers->find(c) >= 0;
      }
      // Both epicondyles (malleoli) on the static trial beat one lateral skin marker on the motion
      // trial: their mean is the joint centre, the lateral marker's is a width estimate.
      if (!jc.empty()) rule(name, {{"marker", jc}}, jc + " (joint centre)");
      else if (!lat.empty() && !med.empty()) rule(name, {{"mean", {lat, med}}}, "mean of " + lat + " and " + med + " (lateral and medial)");
      else if (carried && !slat.empty() && !smed.empty())
        rule(name, {{"static", {slat, smed}}, {"cluster", carrier}},
             "mean of the static trial's " + slat + " and " + smed + ", carried by " + join(carrier));
      else if (!lat.empty()) rule(name, {{"marker", lat}, {"surface", "lateral"}}, lat + " (lateral marker; moved to the joint centre in 3D)");
      else if (carried && !slat.empty())
        rule(name, {{"static", {slat}}, {"cluster", carrier}, {"surface", "lateral"}},
             "the static trial's lateral " + slat + ", carried by " + join(carrier));
      else if (carrier.size() >= 3 && below.size() >= 3)
        rule(name, {{"functional", {{"proximal", carrier}, {"distal", below}}}},
             "functional centre (SCoRE) of " + join(carrier) + " against " + join(below));
      else
        missing(name, "no joint centre (" + spellings_of(centre) + "), no lateral marker (" + spellings_of(lateral) + ")" +
                          (med.empty() ? "" : ", the medial marker " + med + " alone does not make one") + ", and no " +
                          (knee ? "thigh" : "shank") + " cluster of 3 or more markers (RTH1-3, R.Thigh.Upper; RTB1-3, R.Shank.Upper) " +
                          (static_markers ? "on both trials with the static trial's joint markers or " : "with a static trial (--static) or ") +
                          "with a cluster below it for a functional centre");
    }
    if (!heel.empty()) rule("heel_" + s, {{"marker", heel}}, heel);
    else missing("heel_" + s, "no heel marker (" + spellings_of("heel") + ")");
    // The MT head, along the foot's midline where the labels allow.
    bool toe_is_mt = false;
    std::vector<std::string> heads;
    for (const auto* h : {&mt1, &mt2, &mt5})
      if (!h->empty()) heads.push_back(*h);
    if (heads.size() >= 2) rule("mt_" + s, {{"mean", heads}}, "mean of the metatarsal-head markers " + join(heads));
    else if (!mt2.empty()) rule("mt_" + s, {{"marker", mt2}}, mt2 + " (2nd MT head)");
    else if (!mt5.empty()) rule("mt_" + s, {{"marker", mt5}, {"surface", "lateral"}}, mt5 + " (5th MT head, lateral)");
    else if (!toe.empty() && hallux.empty()) {
      rule("mt_" + s, {{"marker", toe}}, toe + " (a toe marker with no MT marker: taken as Plug-in Gait's, on the 2nd MT head)");
      toe_is_mt = true;
    } else if (!mt1.empty()) {
      rule("mt_" + s, {{"marker", mt1}}, mt1 + " (1st MT head alone: the COP's lateral line runs medially of the foot's midline)");
    } else {
      missing("mt_" + s, "no metatarsal-head marker (" + spellings_of("mt1") + "; " + spellings_of("mt5") + "; " + spellings_of("mt2") +
                             "; or a Plug-in Gait TOE)");
    }
    if (!hallux.empty()) rule("hallux_" + s, {{"marker", hallux}}, hallux);
    else if (!toe.empty() && !toe_is_mt) rule("hallux_" + s, {{"marker", toe}}, toe + " (toe marker ahead of the MT markers)");
    else rule("hallux_" + s, {{"virtual_hallux", 0.3}}, "virtual toes, 0.3 x the ankle-MT length (no hallux marker)");
  }

  // The shoulder point: the acromia, else C7 with the sternum's top, else an upright torso.
  const std::string rsho = f.one('r', "shoulder", notes), lsho = f.one('l', "shoulder", notes);
  const std::string c7 = f.one(0, "c7", notes), clav = f.one(0, "clav", notes);
  if (!rsho.empty() && !lsho.empty()) rule("shoulder", {{"mean", {rsho, lsho}}}, "mean of " + rsho + " and " + lsho);
  else if (!c7.empty() && !clav.empty()) rule("shoulder", {{"mean", {c7, clav}}}, "mean of " + c7 + " and " + clav + " (no acromion markers)");
  else if (!pelvis.is_null()) {
    rule("shoulder", {{"pelvis_up", 0.5}, {"sway_gain", 0.5}, {"pelvis", pelvis}},
         "an upright torso of 0.5 m over the hip centre, swaying with the pelvis (no trunk markers hold data)");
  } else {
    missing("shoulder", "no acromion markers (" + spellings_of("shoulder") + "), no C7 with a sternum marker, and no pelvis for an upright torso");
  }

  // The arms and the head (the 3D model's lateral force), where their markers hold data.
  nlohmann::json upper = nlohmann::json::object();
  for (const char side : {'r', 'l'}) {
    const std::string s(1, side);
    if (const std::string& sho = side == 'r' ? rsho : lsho; !sho.empty()) upper["shoulder_" + s] = nlohmann::json::array({sho});
    if (const std::string e = f.one(side, "elbow", notes); !e.empty()) upper["elbow_" + s] = nlohmann::json::array({e});
    if (const auto w = f.all(side, "wrist"); !w.empty()) upper["wrist_" + s] = w;
  }
  std::vector<std::string> head;
  for (const char side : {'r', 'l', '\0'})
    for (const auto& h : f.all(side, "head")) head.push_back(h);
  if (!head.empty()) upper["head"] = head;
  if (!upper.empty()) {
    std::string said;
    for (const auto& [k, v] : upper.items()) said += (said.empty() ? "" : "; ") + k + " " + join(v.get<std::vector<std::string>>());
    out.rules.push_back("upper body (3D model): " + said);
  }

  // The draft: what was found, and a placeholder that names each missing landmark (a mapping file
  // with one still in it is refused, naming it, when read).
  nlohmann::json draft_landmarks = lm;
  for (const auto& x : out.missing) {
    const std::string landmark = x.substr(0, x.find(':'));
    draft_landmarks[landmark] = {{"marker", "FILL IN: " + x}};
  }
  out.draft = {{"name", "labels"}, {"description", "made from the file's marker labels (kin2grf --markers labels)"},
               {"landmarks", draft_landmarks}};
  if (!upper.empty()) out.draft["upper_body"] = upper;
  if (out.missing.empty()) out.mapping = out.draft;
  return out;
}

}  // namespace kin2grf
