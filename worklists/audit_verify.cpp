#include "worklists/audit_verify.h"

#include <sqlite3.h>

#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "core/errors.h"
#include "worklists/audit_cross_check.h"
#include "worklists/audit_trail.h"

namespace mmm::worklists {
namespace {

// How far from its position a moved entry is looked for (seqs either side).
// A farther move is reported as an edit: still caught, only named less well.
constexpr std::int64_t kSearchWindow = 64;

struct CheckedRow {
  AuditRow row;
  std::optional<std::int64_t> origin;  // the seq its hash was computed for
  bool flagged = false;                // already reported (edited, reordered, inserted)
  bool inserted = false;
};

std::string short_hash(const std::string& hash) { return hash.substr(0, 12) + "..."; }

std::string seq_range(std::int64_t first, std::int64_t last) {
  return first == last ? "entry " + std::to_string(first)
                       : "entries " + std::to_string(first) + ".." + std::to_string(last);
}

// The seq `row`'s stored hash was computed for: its own, `hint`, or one within
// kSearchWindow of its own; std::nullopt when none.
std::optional<std::int64_t> find_origin(AuditRow row, std::optional<std::int64_t> hint) {
  const std::int64_t own = row.seq;
  const auto matches = [&row](std::int64_t seq) {
    row.seq = seq;
    return audit_row_hash(row) == row.hash;
  };
  if (matches(own)) return own;
  if (hint && *hint != own && matches(*hint)) return hint;
  if (own <= 0 || own > std::numeric_limits<std::int64_t>::max() - kSearchWindow) {
    return std::nullopt;
  }
  for (std::int64_t distance = 1; distance <= kSearchWindow; ++distance) {
    if (matches(own + distance)) return own + distance;
    if (own - distance >= 1 && matches(own - distance)) return own - distance;
  }
  return std::nullopt;
}

// A head read from meta or the checkpoint: the value, or why it is unusable.
struct ReadHead {
  std::optional<AuditHead> head;
  std::string damage;  // non-empty: unreadable or malformed
};

template <typename Read>
ReadHead read_head(Read read) {
  ReadHead result;
  try {
    result.head = read();
  } catch (const IoError& error) {
    result.damage = error.what();
  }
  return result;
}

// A read transaction for the scope, unless the caller already has one open.
class ReadSnapshot {
 public:
  explicit ReadSnapshot(workflow::Database& database)
      : database_(database), own_(sqlite3_get_autocommit(database.handle()) != 0) {
    if (own_) database_.exec("BEGIN DEFERRED");
  }
  ~ReadSnapshot() {
    if (!own_) return;
    try {
      database_.exec("COMMIT");
    } catch (const workflow::SqliteError&) {  // NOLINT(bugprone-empty-catch): nothing was written
    }
  }
  ReadSnapshot(const ReadSnapshot&) = delete;
  ReadSnapshot& operator=(const ReadSnapshot&) = delete;
  ReadSnapshot(ReadSnapshot&&) = delete;
  ReadSnapshot& operator=(ReadSnapshot&&) = delete;

 private:
  workflow::Database& database_;
  bool own_;
};

class Verifier {
 public:
  Verifier(std::vector<AuditRow> rows, ReadHead meta, ReadHead checkpoint)
      : meta_(std::move(meta)), checkpoint_(std::move(checkpoint)) {
    for (AuditRow& row : rows) rows_.push_back({std::move(row), std::nullopt});
    if (!rows_.empty()) head_ = {rows_.back().row.seq, rows_.back().row.hash};
  }

  AuditVerification run() {
    find_origins();
    mark_duplicates();
    report_rows();
    report_missing();
    report_links();
    report_meta();
    report_checkpoint();
    std::stable_sort(problems_.begin(), problems_.end(), [](const auto& a, const auto& b) {
      return std::pair(a.seq, a.kind) < std::pair(b.seq, b.kind);
    });
    AuditVerification result;
    result.intact = std::all_of(problems_.begin(), problems_.end(),
                                [](const AuditProblem& p) { return is_audit_warning(p.kind); });
    result.problems = std::move(problems_);
    result.entries = static_cast<std::int64_t>(rows_.size());
    result.head_seq = head_.seq;
    result.head = head_.hash;
    return result;
  }

 private:
  void add(AuditProblemKind kind, std::int64_t seq, std::string message) {
    problems_.push_back({kind, seq, std::move(message)});
  }

  void find_origins() {
    std::unordered_map<std::string, std::size_t> by_hash;
    for (std::size_t i = 0; i < rows_.size(); ++i) by_hash.emplace(rows_[i].row.hash, i);
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      CheckedRow& checked = rows_[i];
      // One past the origin of the entry this one says came before it.
      std::optional<std::int64_t> hint;
      if (checked.row.prev_hash == kAuditGenesisHash) hint = 1;
      const auto before = by_hash.find(checked.row.prev_hash);
      if (before != by_hash.end() && before->second < i && rows_[before->second].origin) {
        hint = *rows_[before->second].origin + 1;
      }
      checked.origin = find_origin(checked.row, hint);
    }
  }

  // Two rows with the same origin: the genuine one is the one a later entry
  // links to (or the checkpoint or meta names, or that sits at its own seq).
  void mark_duplicates() {
    std::unordered_set<std::string> linked;
    for (const CheckedRow& checked : rows_) linked.insert(checked.row.prev_hash);
    std::map<std::int64_t, std::vector<std::size_t>> by_origin;
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      if (rows_[i].origin) by_origin[*rows_[i].origin].push_back(i);
    }
    const auto named_by_head = [this](const std::string& hash) {
      return (checkpoint_.head && checkpoint_.head->hash == hash) ||
             (meta_.head && meta_.head->hash == hash);
    };
    for (const auto& group : by_origin) {
      const std::int64_t origin = group.first;
      const std::vector<std::size_t>& indices = group.second;
      if (indices.size() < 2) continue;
      std::size_t genuine = indices.front();
      const auto pick = [&](auto predicate) {
        const auto found = std::find_if(indices.begin(), indices.end(), predicate);
        if (found == indices.end()) return false;
        genuine = *found;
        return true;
      };
      if (!pick([&](std::size_t i) { return linked.contains(rows_[i].row.hash); }) &&
          !pick([&](std::size_t i) { return named_by_head(rows_[i].row.hash); })) {
        pick([&](std::size_t i) { return rows_[i].row.seq == origin; });
      }
      for (const std::size_t i : indices) {
        if (i == genuine) continue;
        rows_[i].inserted = true;
        rows_[i].flagged = true;
        add(AuditProblemKind::kInserted, rows_[i].row.seq,
            "entry " + std::to_string(rows_[i].row.seq) + " is a second entry " +
                std::to_string(origin) + "; the chain continues from the one at seq " +
                std::to_string(rows_[genuine].row.seq) + ": it was inserted outside mmm");
      }
    }
  }

  void report_rows() {
    for (CheckedRow& checked : rows_) {
      if (checked.inserted) continue;
      const std::int64_t seq = checked.row.seq;
      if (seq <= 0) {
        checked.flagged = true;
        add(AuditProblemKind::kInserted, seq,
            "entry " + std::to_string(seq) +
                " has a seq mmm never writes (entries count from 1): it was inserted outside mmm");
      } else if (!checked.origin) {
        checked.flagged = true;
        add(AuditProblemKind::kEdited, seq,
            "entry " + std::to_string(seq) +
                ": the stored hash does not match the content; a field was changed after the "
                "entry was written");
      } else if (*checked.origin != seq) {
        checked.flagged = true;
        add(AuditProblemKind::kReordered, seq,
            "entry " + std::to_string(seq) + " holds the entry written as seq " +
                std::to_string(*checked.origin) + ": entries were swapped or renumbered");
      }
    }
  }

  // Origins 1..last that no row accounts for, as runs [first, last].
  void report_missing() {
    std::set<std::int64_t> covered;
    for (const CheckedRow& checked : rows_) {
      if (checked.inserted || checked.row.seq <= 0) continue;
      covered.insert(checked.origin.value_or(checked.row.seq));
    }
    std::int64_t expected = 1;
    for (const std::int64_t seq : covered) {
      if (seq > expected) {
        missing_.emplace_back(expected, seq - 1);
        add(AuditProblemKind::kDeleted, expected,
            seq_range(expected, seq - 1) + " missing from the middle of the trail: deleted");
      }
      expected = seq + 1;
    }
    last_origin_ = expected - 1;
  }

  [[nodiscard]] bool missing_between(std::int64_t after, std::int64_t before) const {
    return std::any_of(missing_.begin(), missing_.end(),
                       [&](const auto& run) { return run.first < before && run.second > after; });
  }

  void report_links() {
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      CheckedRow& checked = rows_[i];
      const bool first = i == 0;
      const std::string& expected = first ? std::string(kAuditGenesisHash) : rows_[i - 1].row.hash;
      if (checked.row.prev_hash == expected) continue;
      const std::int64_t after = first ? 0 : rows_[i - 1].row.seq;
      if (checked.flagged || (!first && rows_[i - 1].flagged) ||
          missing_between(after, checked.row.seq)) {
        continue;
      }
      if (first) {
        checked.flagged = true;
        add(AuditProblemKind::kEdited, checked.row.seq,
            "entry " + std::to_string(checked.row.seq) +
                ": prev_hash is not that of a first entry, and its hash was recomputed to match: "
                "it was changed");
      } else {
        rows_[i - 1].flagged = true;
        add(AuditProblemKind::kEdited, after,
            "entry " + std::to_string(after) +
                ": its hash is not the prev_hash recorded by entry " +
                std::to_string(checked.row.seq) +
                "; it was changed and its hash recomputed (or entry " +
                std::to_string(checked.row.seq) + " was re-linked)");
      }
    }
  }

  // The genuine row written as `seq`, if any.
  [[nodiscard]] const CheckedRow* row_written_as(std::int64_t seq) const {
    const auto found = std::find_if(rows_.begin(), rows_.end(), [seq](const CheckedRow& c) {
      return !c.inserted && c.origin == seq;
    });
    return found == rows_.end() ? nullptr : &*found;
  }

  void report_meta() {
    const std::string where = "meta 'audit_head'";
    if (!meta_.damage.empty()) {
      add(AuditProblemKind::kMetaMismatch, head_.seq, meta_.damage);
      return;
    }
    if (!meta_.head) {
      if (!rows_.empty()) {
        add(AuditProblemKind::kMetaMismatch, head_.seq,
            where + " is missing although the trail has " + std::to_string(rows_.size()) +
                " entries: it was deleted");
      }
      return;
    }
    const AuditHead& meta = *meta_.head;
    if (meta == head_) return;
    // Rows past a meta head that is right (and past the checkpoint) were never
    // committed by append_audit_entry, which moves meta with every entry.
    const CheckedRow* named = row_written_as(meta.seq);
    const bool checkpoint_before = !checkpoint_.head || checkpoint_.head->seq <= meta.seq;
    if (meta.seq > 0 && meta.seq < head_.seq && named != nullptr && named->row.hash == meta.hash &&
        checkpoint_before) {
      for (CheckedRow& checked : rows_) {
        if (checked.row.seq <= meta.seq || checked.flagged) continue;
        checked.flagged = true;
        appended_outside_ = true;
        add(AuditProblemKind::kInserted, checked.row.seq,
            "entry " + std::to_string(checked.row.seq) + " lies past the head " + where +
                " records (seq " + std::to_string(meta.seq) +
                "), which mmm moves with every entry: it was added outside mmm");
      }
      return;
    }
    add(AuditProblemKind::kMetaMismatch, head_.seq,
        where + " records seq " + std::to_string(meta.seq) + " (hash " + short_hash(meta.hash) +
            ") but the trail ends at seq " + std::to_string(head_.seq) + " (hash " +
            short_hash(head_.hash) + "); both are written in one transaction, so the database " +
            "was edited");
  }

  void report_checkpoint() {
    const std::string where = "the checkpoint file";
    if (!checkpoint_.damage.empty()) {
      add(AuditProblemKind::kCheckpointDamaged, 0, checkpoint_.damage);
      return;
    }
    if (!checkpoint_.head) {
      if (!rows_.empty()) {
        add(AuditProblemKind::kCheckpointMissing, 0,
            where + " audit.checkpoint is missing although the trail has " +
                std::to_string(rows_.size()) + " entries: it was deleted");
      }
      return;
    }
    const AuditHead& checkpoint = *checkpoint_.head;
    const std::int64_t top = std::max(last_origin_, head_.seq);
    if (checkpoint.seq == 0 && checkpoint.hash != kAuditGenesisHash) {
      add(AuditProblemKind::kCheckpointDamaged, 0,
          where + " records seq 0 with a hash other than 64 zeros: it was edited");
      return;
    }
    if (checkpoint.seq > top) {
      add(AuditProblemKind::kTruncated, top + 1,
          where + " records seq " + std::to_string(checkpoint.seq) + " but the trail ends at seq " +
              std::to_string(top) + ": " + seq_range(top + 1, checkpoint.seq) +
              " were deleted from the end");
      return;
    }
    if (checkpoint.seq > 0) {
      const CheckedRow* named = row_written_as(checkpoint.seq);
      if (named == nullptr) return;  // reported as deleted
      if (named->row.hash != checkpoint.hash) {
        add(AuditProblemKind::kCheckpointMismatch, checkpoint.seq,
            where + " records hash " + short_hash(checkpoint.hash) + " for entry " +
                std::to_string(checkpoint.seq) + ", the database has " +
                short_hash(named->row.hash) + ": the chain up to there was rewritten and rehashed");
        return;
      }
    }
    if (checkpoint.seq < head_.seq && !appended_outside_) {
      add(AuditProblemKind::kCheckpointBehind, checkpoint.seq + 1,
          where + " records seq " + std::to_string(checkpoint.seq) + ", the trail ends at seq " +
              std::to_string(head_.seq) + ": " + seq_range(checkpoint.seq + 1, head_.seq) +
              " were committed but not checkpointed (a crash between commit and checkpoint "
              "write; the next checkpoint write covers them)");
    }
  }

  std::vector<CheckedRow> rows_;
  ReadHead meta_;
  ReadHead checkpoint_;
  AuditHead head_;
  std::vector<std::pair<std::int64_t, std::int64_t>> missing_;
  std::int64_t last_origin_ = 0;
  bool appended_outside_ = false;
  std::vector<AuditProblem> problems_;
};

}  // namespace

std::string_view audit_problem_kind_name(AuditProblemKind kind) {
  switch (kind) {
    case AuditProblemKind::kEdited:
      return "edited";
    case AuditProblemKind::kDeleted:
      return "deleted";
    case AuditProblemKind::kReordered:
      return "reordered";
    case AuditProblemKind::kTruncated:
      return "truncated";
    case AuditProblemKind::kInserted:
      return "inserted";
    case AuditProblemKind::kCheckpointMissing:
      return "checkpoint_missing";
    case AuditProblemKind::kCheckpointDamaged:
      return "checkpoint_damaged";
    case AuditProblemKind::kCheckpointMismatch:
      return "checkpoint_mismatch";
    case AuditProblemKind::kCheckpointBehind:
      return "checkpoint_behind";
    case AuditProblemKind::kMetaMismatch:
      return "meta_mismatch";
    case AuditProblemKind::kTaskUnaudited:
      return "task_unaudited";
    case AuditProblemKind::kValueMismatch:
      return "value_mismatch";
    case AuditProblemKind::kArtifactChanged:
      return "artifact_changed";
    case AuditProblemKind::kAnchorMissing:
      return "anchor_missing";
    case AuditProblemKind::kAnchorMismatch:
      return "anchor_mismatch";
  }
  return "unknown";
}

bool is_audit_warning(AuditProblemKind kind) { return kind == AuditProblemKind::kCheckpointBehind; }

AuditVerification verify_audit(workflow::Database& database,
                               const std::filesystem::path& study_dir) {
  // The checkpoint first: it is written after the commit, so an honest
  // database read afterwards is never behind it. Meta and rows from one
  // snapshot, so that an entry committed meanwhile cannot split them.
  ReadHead checkpoint = read_head([&study_dir] { return read_audit_checkpoint(study_dir); });
  const ReadSnapshot snapshot(database);
  ReadHead meta = read_head([&database] { return read_audit_meta_head(database); });
  AuditVerification verification =
      Verifier(read_audit_rows(database), std::move(meta), std::move(checkpoint)).run();
  for (AuditProblem& problem : cross_check_tasks(database, study_dir)) {
    verification.problems.push_back(std::move(problem));
    verification.intact = false;
  }
  return verification;
}

}  // namespace mmm::worklists
