#include "map_aided_fusion/replay/report.hpp"

#include <sstream>
#include <utility>

#include "map_aided_fusion/eval/movers.hpp"

namespace map_aided_fusion {
namespace replay {

std::string deskewSummary(const std::map<std::string, std::size_t>& status)
{
  std::string out;
  for (const auto& s : status) out += (out.empty() ? "" : ", ") + s.first + " " + std::to_string(s.second);
  return out.empty() ? "none" : out;
}

std::string moversSection(const std::vector<eval::VariantScores>& scores, bool objects_only)
{
  std::vector<std::pair<std::string, const eval::MoverScorer*>> main_rows, all_rows;
  for (const auto& v : scores)
  {
    if (v.movers.stamps().empty()) continue;
    all_rows.emplace_back(v.name, &v.movers);
    if (v.name == "default" || v.name == "paper" || v.name.rfind("live", 0) == 0) main_rows.emplace_back(v.name, &v.movers);
  }
  if (all_rows.empty()) return "";
  std::ostringstream out;
  out << (objects_only ? "" : "## Moving objects\n\n")
      << "Movers per kind (doc/evaluation.md, \"Scoring moving objects\", defines seen, V, S and false V):\n\n"
      << eval::moversMarkdown(main_rows, true);
  if (all_rows.size() > main_rows.size())
    out << "\nEvery variant, all kinds:\n\n" << eval::moversMarkdown(all_rows, false);
  for (const auto& [name, scorer] : main_rows)
    out << "\nPer mover, `" << name << "`:\n\n" << eval::moverObjectsMarkdown(*scorer);
  return out.str();
}

std::string tracksSection(const std::vector<eval::VariantScores>& scores)
{
  const std::string table = eval::tracksMarkdown(scores);
  if (table.empty()) return "";
  return "\n## Tracks (CLEAR-MOT of the moving tracks against the movers, match distance 2 m)\n\n" + table;
}

}  // namespace replay
}  // namespace map_aided_fusion
