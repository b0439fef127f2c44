/**
 * @file
 * @brief Tracking, part "lifecycle": a track is born tentative, confirmed after confirm_hits consecutive
 *        associations, coasts while unseen and is deleted when a tentative track misses once or a coasting one stays
 *        unseen longer than max_coast_time (the spawn / confirm / coast / prune cycle of the field's trackers).
 */
#pragma once

namespace map_aided_fusion {
namespace core {

/// Lifecycle of a track.
enum class TrackState : unsigned char
{
  kTentative,  ///< fewer than confirm_hits associations so far
  kConfirmed,
  kCoasting,   ///< confirmed, not associated in the last scan(s)
};

/// What the lifecycle reads (TrackerParams' fields of the same names).
struct LifecycleParams
{
  int confirm_hits = 3;         ///< consecutive associations that confirm a tentative track
  double max_coast_time = 0.5;  ///< s without an association before a confirmed track is deleted
};

/// The state of a track just born (one association).
inline TrackState bornState(const LifecycleParams& p)
{
  return p.confirm_hits <= 1 ? TrackState::kConfirmed : TrackState::kTentative;
}

/// The state after an association that makes @p consecutive_hits in a row.
inline TrackState afterHit(TrackState s, int consecutive_hits, const LifecycleParams& p)
{
  if (s == TrackState::kCoasting || (s == TrackState::kTentative && consecutive_hits >= p.confirm_hits))
    return TrackState::kConfirmed;
  return s;
}

/// The state after a scan without an association.
inline TrackState afterMiss(TrackState s) { return s == TrackState::kConfirmed ? TrackState::kCoasting : s; }

/// True when a track in state @p s is deleted: a tentative track @p missed this scan, or a coasting one unseen for
/// more than max_coast_time (@p unseen_for, s).
inline bool expired(TrackState s, bool missed, double unseen_for, const LifecycleParams& p)
{
  return (s == TrackState::kTentative && missed) || (s == TrackState::kCoasting && unseen_for > p.max_coast_time);
}

}  // namespace core
}  // namespace map_aided_fusion
