#include "workflow/run/run_study.h"

#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "core/errors.h"
#include "workflow/definition/workflow_graph.h"
#include "workflow/fault_injection.h"
#include "workflow/host_and_time.h"
#include "workflow/run/crash_marker.h"
#include "workflow/run/export_outputs.h"
#include "workflow/run/node_execution.h"
#include "workflow/run/study_plan.h"
#include "workflow/study/crash_records.h"

namespace mmm::workflow {
namespace {

using Clock = std::chrono::steady_clock;
using Available = std::map<std::string, std::map<std::string, OutputArtifact>>;

// Completed jobs, from the workers to the scheduler thread.
class CompletionQueue {
 public:
  void push(Completion completion) {
    {
      const std::lock_guard lock(mutex_);
      done_.push_back(std::move(completion));
    }
    ready_.notify_one();
  }

  // Waits until at least one completion is there, or `deadline` passes;
  // returns what is there (possibly nothing).
  std::vector<Completion> take(std::optional<Clock::time_point> deadline) {
    std::unique_lock lock(mutex_);
    const auto any = [this] { return !done_.empty(); };
    if (deadline) {
      ready_.wait_until(lock, *deadline, any);
    } else {
      ready_.wait(lock, any);
    }
    std::vector<Completion> taken(std::make_move_iterator(done_.begin()),
                                  std::make_move_iterator(done_.end()));
    done_.clear();
    return taken;
  }

 private:
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Completion> done_;
};

// A fixed set of worker threads taking jobs in order.
class WorkerPool {
 public:
  WorkerPool(int threads, std::function<void(Job&)> work) : work_(std::move(work)) {
    for (int i = 0; i < threads; ++i) {
      workers_.emplace_back([this](const std::stop_token& stop) { loop(stop); });
    }
  }
  ~WorkerPool() {
    for (std::jthread& worker : workers_) worker.request_stop();
    wake_.notify_all();
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  WorkerPool(WorkerPool&&) = delete;
  WorkerPool& operator=(WorkerPool&&) = delete;

  void submit(Job job) {
    {
      const std::lock_guard lock(mutex_);
      jobs_.push_back(std::move(job));
    }
    wake_.notify_one();
  }

 private:
  void loop(const std::stop_token& stop) {
    while (true) {
      Job job;
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, stop, [this] { return !jobs_.empty(); });
        // Stopping: the scheduler is gone (normally nothing is queued then;
        // after a store failure the queued nodes are simply not run).
        if (stop.stop_requested()) return;
        job = std::move(jobs_.front());
        jobs_.pop_front();
      }
      work_(job);
    }
  }

  std::function<void(Job&)> work_;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::deque<Job> jobs_;
  std::vector<std::jthread> workers_;  // last: joined first, before the queue dies
};

// Group commit: one write transaction stays open while rows accumulate and
// is committed when it is `interval` old (or on demand). The artifacts the
// rows refer to are flushed to disk first (one syncfs for all of them: the
// store runs in Durability::kDeferred mode during a run).
class BatchWriter {
 public:
  BatchWriter(Database& database, const ArtifactStore& artifacts,
              std::chrono::milliseconds interval)
      : database_(&database), artifacts_(&artifacts), interval_(interval) {}

  Database& write() {
    if (!transaction_) {
      transaction_.emplace(*database_);
      deadline_ = Clock::now() + interval_;
    }
    return *database_;
  }
  void commit() {
    if (!transaction_) return;
    artifacts_->sync_all();
    fault_point("run.before_commit");
    transaction_->commit();
    transaction_.reset();
    fault_point("run.after_commit");
  }
  void commit_if_due() {
    if (transaction_ && Clock::now() >= deadline_) commit();
  }
  [[nodiscard]] std::optional<Clock::time_point> deadline() const {
    if (!transaction_) return std::nullopt;
    return deadline_;
  }

 private:
  Database* database_;
  const ArtifactStore* artifacts_;
  std::chrono::milliseconds interval_;
  std::optional<Transaction> transaction_;
  Clock::time_point deadline_;
};

// Puts the store in deferred-sync mode for the lifetime of the object.
class DeferredSync {
 public:
  explicit DeferredSync(ArtifactStore& artifacts)
      : artifacts_(&artifacts), before_(artifacts.durability()) {
    artifacts.set_durability(Durability::kDeferred);
  }
  ~DeferredSync() { artifacts_->set_durability(before_); }
  DeferredSync(const DeferredSync&) = delete;
  DeferredSync& operator=(const DeferredSync&) = delete;
  DeferredSync(DeferredSync&&) = delete;
  DeferredSync& operator=(DeferredSync&&) = delete;

 private:
  ArtifactStore* artifacts_;
  Durability before_;
};

void clear_folder(const std::filesystem::path& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    std::filesystem::remove_all(entry.path(), error);
  }
}

// The scheduler of one run; lives for the duration of run_study().
class Scheduler {
 public:
  Scheduler(Study& study, const RunOptions& options)
      : study_(study),
        durability_(study.artifacts()),
        options_(options),
        batch_(study.database(), study.artifacts(), options.commit_interval),
        pool_(std::max(1, options.jobs), [this](Job& job) {
          if (options_.executor == Executor::kSlurm) {
            completions_.push(execute_on_slurm(job, study_.artifacts().root(),
                                               study_.artifacts().pool(), scratch_root_,
                                               options_.slurm, options_.observer));
          } else {
            completions_.push(
                execute(job, study_.artifacts(), scratch_root_, crash_marker_, options_.observer));
          }
        }) {}

  RunSummary run() {
    const auto start = Clock::now();
    prepare();
    const std::vector<std::string> order = topological_order(study_.workflow());
    if (observer() != nullptr)
      observer()->run_started(static_cast<int>(order.size()), options_.jobs);
    for (const std::string& message : summary_.input_changes) {
      if (observer() != nullptr) observer()->input_changed(message);
    }
    build_graph(order);
    for (const std::string& id : order) {
      if (waiting_for_.at(id) == 0) ready_.push_back(id);
    }
    while (true) {
      while (!ready_.empty()) {
        const std::string id = ready_.front();
        ready_.pop_front();
        schedule(id);
      }
      if (running_ == 0) break;
      for (Completion& completion : completions_.take(batch_.deadline())) finish(completion);
      batch_.commit_if_due();
    }
    batch_.commit();
    for (const std::string& id : order) {
      if (!settled_.contains(id)) summary_.blocked.push_back(id);
    }
    summary_.exported = export_outputs(study_, available_).written;
    summary_.outcome = !summary_.failed.empty()    ? RunOutcome::kFailed
                       : !summary_.waiting.empty() ? RunOutcome::kWaiting
                       : summary_.blocked.empty()  ? RunOutcome::kDone
                                                   : RunOutcome::kFailed;
    summary_.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    record_run_end();
    if (observer() != nullptr) observer()->run_finished(summary_);
    return summary_;
  }

 private:
  RunObserver* observer() const { return options_.observer; }

  void prepare() {
    study_.artifacts().remove_temporaries();
    clear_folder(study_.scratch_dir());
    summary_.input_changes = study_.refresh_file_inputs();
    inputs_ = study_.inputs();
    Database& database = study_.database();
    Transaction transaction(database);
    // The nodes that crashed the process are recorded first (their executions
    // become 'failed'); whatever else was running was interrupted.
    const std::vector<MarkedCrash> crashes = read_crash_marker(crash_marker_);
    for (const MarkedCrash& crash : crashes) {
      record_crash(database, {crash.node, crash.cache_key, crash.signal, utc_now()});
    }
    mark_interrupted(database);
    database
        .prepare(
            "INSERT INTO runs(started_at, status, host, pid, mmm_version, git_revision, "
            "workflow_hash, jobs) VALUES (?, 'running', ?, ?, ?, ?, ?, ?)")
        .bind_text(1, utc_now())
        .bind_text(2, host_name())
        .bind_int64(3, ::getpid())
        .bind_text(4, options_.provenance.mmm_version)
        .bind_text(5, options_.provenance.git_revision)
        .bind_text(6, workflow_hash(study_.workflow()))
        .bind_int64(7, std::max(1, options_.jobs))
        .step();
    summary_.run_id = database.last_insert_rowid();
    transaction.commit();
    std::error_code ignored;
    std::filesystem::remove(crash_marker_, ignored);
    fault_point("run.started");
  }

  void build_graph(const std::vector<std::string>& order) {
    for (const std::string& id : order) {
      std::set<std::string> upstream;
      for (const auto& [port, connection] : study_.workflow().find_node(id)->inputs) {
        if (!connection.source.is_study()) upstream.insert(connection.source.node);
      }
      waiting_for_[id] = static_cast<int>(upstream.size());
      for (const std::string& source : upstream) dependents_[source].push_back(id);
    }
  }

  void schedule(const std::string& id) {
    fault_point("run.schedule");
    const NodeInstance& node = *study_.workflow().find_node(id);
    const NodeType* type = study_.registry().find(node.type);
    std::vector<std::string> missing;
    std::map<std::string, ArtifactRef> inputs =
        resolve_inputs(node, type->spec, available_, inputs_, study_.artifacts(), missing);
    CacheKeyParts parts;
    try {
      parts = key_parts_for(type->spec, study_.given_params(node), inputs);
    } catch (const InvalidInputError& e) {
      record_invalid(node, *type, e.what());
      return;
    }
    const std::string key = cache_key(parts);
    Database& database = batch_.write();
    const std::string* manual_node = type->spec.is_manual() ? &id : nullptr;
    std::optional<ExecutionRecord> result = find_result(database, key, manual_node);
    if (result && outputs_present(*result, study_.artifacts())) {
      summary_.cached.push_back(id);
      if (observer() != nullptr) observer()->node_cached(id);
      complete(id, result->outputs);
      return;
    }
    if (type->spec.is_manual()) {
      summary_.waiting.push_back(id);
      settled_.insert(id);
      if (observer() != nullptr) observer()->node_waiting(id);
      return;
    }
    if (!options_.retry_crashed) {
      if (const std::optional<CrashRecord> crash = find_crash(database, id, key)) {
        record_crashed(node, *type, parts, *crash, inputs);
        return;
      }
    }
    ExecutionRecord record;
    record.run_id = summary_.run_id;
    record.node = id;
    record.node_type = type->spec.name();
    record.version = type->spec.version();
    record.cache_key = key;
    record.reason =
        why_it_runs(last_done_execution(database, id), last_execution(database, id), parts, key);
    record.started_at = utc_now_precise();
    record.host = host_name();
    record.pid = ::getpid();
    record.key_parts = parts;
    const std::int64_t execution_id = insert_execution(database, record);
    running_records_[id] = record;
    ++running_;
    if (observer() != nullptr) observer()->node_started(id, record.node_type, record.reason);
    pool_.submit(Job{id, execution_id, key, type, std::move(inputs), std::move(parts.params)});
  }

  void record_invalid(const NodeInstance& node, const NodeType& type, const std::string& error) {
    ExecutionRecord record;
    record.run_id = summary_.run_id;
    record.node = node.id;
    record.node_type = type.spec.name();
    record.version = type.spec.version();
    record.status = ExecutionStatus::kFailed;
    record.reason = "invalid parameters";
    record.error = error;
    record.started_at = record.finished_at = utc_now_precise();
    record.host = host_name();
    record.pid = ::getpid();
    record.key_parts.node_type = record.node_type;
    record.key_parts.version = record.version;
    insert_execution(batch_.write(), record);
    summary_.failed.push_back(node.id);
    settled_.insert(node.id);
    if (observer() != nullptr) observer()->node_finished(node.id, false, 0, error);
  }

  // A node that crashed the process with this cache key is not run again:
  // it fails, naming the crash and the user's files it reads.
  void record_crashed(const NodeInstance& node, const NodeType& type, const CacheKeyParts& parts,
                      const CrashRecord& crash, const std::map<std::string, ArtifactRef>& inputs) {
    ExecutionRecord record;
    record.run_id = summary_.run_id;
    record.node = node.id;
    record.node_type = type.spec.name();
    record.version = type.spec.version();
    record.cache_key = crash.cache_key;
    record.key_parts = parts;
    record.status = ExecutionStatus::kFailed;
    record.reason = "it crashed mmm with these inputs and parameters; not run again";
    record.error = crash_error(crash);
    std::string files;
    for (const auto& [port, ref] : inputs) {
      for (const auto& [name, input] : inputs_) {
        if (!input.is_file || input.hash != ref.hash) continue;
        files.append(files.empty() ? "'" : ", '").append(input.given);
        files.append("' (study input '").append(name).append("', read as '").append(port);
        files.append("')");
      }
    }
    if (!files.empty()) record.error += "; the files it reads: " + files;
    record.started_at = record.finished_at = utc_now_precise();
    record.host = host_name();
    record.pid = ::getpid();
    insert_execution(batch_.write(), record);
    summary_.failed.push_back(node.id);
    settled_.insert(node.id);
    if (observer() != nullptr) observer()->node_finished(node.id, false, 0, record.error);
  }

  // A node's error names the files it read by their place in the store
  // (artifacts/ab/cdef...); the person running the study knows the file they
  // gave: name it, with the input's name.
  [[nodiscard]] std::string naming_user_files(std::string error) const {
    for (const auto& [name, input] : inputs_) {
      if (!input.is_file || input.hash.empty()) continue;
      const std::string user_file = "'" + input.given + "' (study input '" + name + "')";
      for (const std::string& stored :
           {study_.artifacts().path_of(input.hash).string(),
            ArtifactStore::relative_path_of(input.hash).generic_string()}) {
        for (std::size_t at = error.find(stored); at != std::string::npos;
             at = error.find(stored, at + user_file.size())) {
          error.replace(at, stored.size(), user_file);
        }
      }
    }
    return error;
  }

  void finish(Completion& completion) {
    --running_;
    ExecutionRecord& record = running_records_.at(completion.node);
    record.finished_at = utc_now_precise();
    record.seconds = completion.seconds;
    if (!completion.error.empty()) {
      completion.error = naming_user_files(completion.error);
      if (!completion.logs.empty()) completion.logs.back().message = completion.error;
    }
    record.error = completion.error;
    record.outputs = completion.outputs;
    record.status = completion.error.empty() ? ExecutionStatus::kDone : ExecutionStatus::kFailed;
    finish_execution(batch_.write(), completion.execution_id, record, completion.logs);
    if (observer() != nullptr) {
      observer()->node_finished(completion.node, completion.error.empty(), completion.seconds,
                                completion.error);
    }
    if (completion.error.empty()) {
      summary_.executed.push_back(completion.node);
      complete(completion.node, completion.outputs);
    } else {
      summary_.failed.push_back(completion.node);
      settled_.insert(completion.node);
    }
    running_records_.erase(completion.node);
  }

  // The node has a current result: its dependents may become ready.
  void complete(const std::string& id, const std::map<std::string, OutputArtifact>& outputs) {
    available_[id] = outputs;
    settled_.insert(id);
    const auto dependents = dependents_.find(id);
    if (dependents == dependents_.end()) return;
    for (const std::string& dependent : dependents->second) {
      if (--waiting_for_.at(dependent) == 0) ready_.push_back(dependent);
    }
  }

  void record_run_end() {
    Database& database = study_.database();
    Transaction transaction(database);
    database
        .prepare(
            "UPDATE runs SET finished_at = ?, status = ?, executed = ?, cached = ?, failed = ?, "
            "waiting = ? WHERE id = ?")
        .bind_text(1, utc_now())
        .bind_text(2, run_outcome_name(summary_.outcome))
        .bind_int64(3, static_cast<std::int64_t>(summary_.executed.size()))
        .bind_int64(4, static_cast<std::int64_t>(summary_.cached.size()))
        .bind_int64(5, static_cast<std::int64_t>(summary_.failed.size()))
        .bind_int64(6, static_cast<std::int64_t>(summary_.waiting.size()))
        .bind_int64(7, summary_.run_id)
        .step();
    transaction.commit();
    fault_point("run.finished");
  }

  Study& study_;
  DeferredSync durability_;
  const RunOptions& options_;
  std::filesystem::path scratch_root_ = study_.scratch_dir();
  std::filesystem::path crash_marker_ = study_.crash_marker();
  CrashHandlers crash_handlers_;
  RunSummary summary_;
  std::map<std::string, StudyInputRecord> inputs_;
  std::map<std::string, int> waiting_for_;  // node -> upstream nodes without a result
  std::map<std::string, std::vector<std::string>> dependents_;
  std::deque<std::string> ready_;
  std::set<std::string> settled_;  // has a result, failed or waits
  Available available_;
  std::map<std::string, ExecutionRecord> running_records_;
  int running_ = 0;
  BatchWriter batch_;
  CompletionQueue completions_;
  WorkerPool pool_;  // last: its threads stop before the rest goes away
};

}  // namespace

std::string_view run_outcome_name(RunOutcome outcome) {
  switch (outcome) {
    case RunOutcome::kDone:
      return "done";
    case RunOutcome::kWaiting:
      return "waiting";
    case RunOutcome::kFailed:
      return "failed";
  }
  return "unknown";
}

RunSummary run_study(Study& study, const StudyLock& lock, const RunOptions& options) {
  if (std::filesystem::absolute(lock.study()).lexically_normal() != study.dir()) {
    throw InvalidInputError("run_study: the lock held is for " + lock.study().string() +
                            ", not for the study " + study.dir().string());
  }
  Scheduler scheduler(study, options);
  return scheduler.run();
}

}  // namespace mmm::workflow
