// kin2grf trial lists: the file `study`, `fit-cop` and `batch` read. One trial a line:
//   activity|lab|name|TRIAL [settings as on the command line] [--plates FILE]
// '#' starts a comment line; the older "activity|name|TRIAL" is read with each trial its own lab;
// a plain line "TRIAL [options]" is the trial named by its file, activity "trials", its own lab.
// Paths are as written (relative to the working directory).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "kin2grf/trial.hpp"
#include "kin2grf/markers/landmarks.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/workflow/settings.hpp"

namespace kin2grf {

struct TrialListEntry {
  std::string activity, lab, name;
  Settings settings;
  std::string plates;  ///< measured forces from this file instead of the trial's plates
  int line = 0;        ///< line number in the list (1-based)
};

/// One line (not a comment); `where` names it in errors ("list.txt:12").
TrialListEntry parse_trial_list_line(const std::string& line, const std::string& where);
/// Every trial of the file; InputError naming the file and line on a bad one, or when empty.
/// Lines end with LF, CRLF or CR; a UTF-8 byte-order mark is skipped.
std::vector<TrialListEntry> read_trial_list(const std::string& path);
/// The same for a list's text; `path` names it in errors.
std::vector<TrialListEntry> parse_trial_list(std::string_view text, const std::string& path);
/// A trial line is at most this long, with at most this many words of options (a hostile list
/// is refused at once, not after seconds of parsing).
inline constexpr std::size_t kMaxTrialLineChars = 65536, kMaxTrialLineWords = 1000;

/// Every file the entries read (trials, static trials, plates, mapping and COP-function files):
/// what no output of a run over them may replace.
std::vector<std::string> list_input_files(const std::vector<TrialListEntry>& entries);

/// Entries for trial files given one by one (the same settings and plates file for all): each its
/// own lab, named by its file name, activity "trials".
std::vector<TrialListEntry> trial_list_of_files(const std::vector<std::string>& files, const Settings& settings,
                                                const std::string& plates);

/// A list's trials for a study or a fit, each loaded when it is used and let go after (its trial,
/// static trial, plates, its own or --plates with plate offsets removed from unloaded samples, and
/// marker set): memory does not grow with the number of trials. Every file is checked to exist
/// now; InputError naming the file when one does not, or later when one cannot be read or has no
/// plates.
std::vector<StudyTrial> study_trials(const std::vector<TrialListEntry>& entries);

}  // namespace kin2grf
