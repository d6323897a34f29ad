#include "ground/ceopt/landing_study.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "tools/study/note.hpp"

namespace aerie::ceopt {

namespace {

// A batch as bytes (exact gains), what rank 0 broadcasts and each batch's study definition.
std::string encode(const std::vector<LandingJob>& jobs) {
  study::NoteWriter n;
  n.integer(static_cast<int64_t>(jobs.size()));
  for (const auto& j : jobs) {
    n.integer(static_cast<int64_t>(j.x.size()));
    for (double v : j.x) n.real(v);
    n.integer(static_cast<int64_t>(j.seeds.first)).integer(j.seeds.count);
  }
  return n.str();
}

std::vector<LandingJob> decode(const std::string& bytes) {
  study::NoteReader in(bytes, "aerie-ceopt: the batch from rank 0");
  std::vector<LandingJob> jobs(static_cast<size_t>(in.integer()));
  for (auto& j : jobs) {
    j.x.resize(static_cast<size_t>(in.integer()));
    for (double& v : j.x) v = in.real();
    j.seeds.first = static_cast<uint64_t>(in.integer());
    j.seeds.count = static_cast<int>(in.integer());
  }
  in.end();
  return jobs;
}

std::string run_note(const LandingRun& r) {
  study::NoteWriter n;
  n.integer(static_cast<int64_t>(r.seed)).integer(r.success).integer(r.collided).real(r.touchdown_error_m).real(r.time_s);
  n.real(r.sim_s).real(r.wall_s).integer(r.losses);
  return n.str();
}

LandingRun run_from_note(const std::string& note) {
  study::NoteReader in(note, "aerie-ceopt: a landing's note");
  LandingRun r;
  r.seed = static_cast<uint64_t>(in.integer());
  r.success = in.integer() != 0;
  r.collided = in.integer() != 0;
  r.touchdown_error_m = in.real();
  r.time_s = in.real();
  r.sim_s = in.real();
  r.wall_s = in.real();
  r.losses = static_cast<int>(in.integer());
  in.end();
  return r;
}

// The batch's study: run i is landing i of the jobs' landings, job by job; `runs` (on the
// writer) receives them as they are written.
struct Batch {
  std::vector<LandingJob> jobs;
  std::vector<std::pair<size_t, int>> where;  // run -> (job, seed offset)
  std::vector<std::vector<LandingRun>> runs;
  study::Study study;
};

std::unique_ptr<Batch> make_batch(const LandingTuning& problem, const std::string& bytes, const std::string& dir) {
  auto b = std::make_unique<Batch>();
  b->jobs = decode(bytes);
  for (size_t j = 0; j < b->jobs.size(); ++j) {
    b->runs.emplace_back(static_cast<size_t>(b->jobs[j].seeds.count));
    for (int k = 0; k < b->jobs[j].seeds.count; ++k) b->where.emplace_back(j, k);
  }
  Batch* batch = b.get();
  study::Study& st = b->study;
  st.tool = "aerie-ceopt";
  st.dir = dir;
  st.runs = static_cast<int>(b->where.size());
  st.outputs = {{"landings.csv", "candidate,seed,success,collision,touchdown_error_m,time_s,losses,sim_s,wall_s\n"}};
  st.definition = "aerie-ceopt landing batch (gains x seeds): " + bytes;
  auto seed_of = [batch](int i) {
    const auto [j, k] = batch->where[static_cast<size_t>(i)];
    return batch->jobs[j].seeds.first + static_cast<uint64_t>(k);
  };
  st.run = [batch, &problem, seed_of](int i) {
    const size_t j = batch->where[static_cast<size_t>(i)].first;
    const LandingRun r = problem.fly(batch->jobs[j].x, {seed_of(i), 1}).front();
    std::ostringstream row;
    row << j << ',' << r.seed << ',' << r.success << ',' << r.collided << ',' << r.touchdown_error_m << ',' << r.time_s << ','
        << r.losses << ',' << r.sim_s << ',' << r.wall_s << '\n';
    return study::Record{{row.str()}, run_note(r), ""};
  };
  st.describe = [batch, seed_of](int i) {
    return "landing of candidate " + std::to_string(batch->where[static_cast<size_t>(i)].first) + " with seed " +
           std::to_string(seed_of(i)) + " (" + batch->study.dir + ")";
  };
  st.on_written = [batch](int i, const study::Record& r) {
    if (r.failed()) return;
    const auto [j, k] = batch->where[static_cast<size_t>(i)];
    batch->runs[j][static_cast<size_t>(k)] = run_from_note(r.note);
  };
  return b;
}

}  // namespace

LandingFlier landing_study_flier(const LandingTuning& problem, const LandingStudyOptions& options,
                                 const study::Session& session) {
  auto count = std::make_shared<int>(0);
  return [&problem, options, &session, count](const std::vector<LandingJob>& jobs) {
    char name[32];
    std::snprintf(name, sizeof name, "/batch-%03d", (*count)++);
    const std::string bytes = session.broadcast(encode(jobs));
    const auto batch = make_batch(problem, bytes, options.dir + name);
    study::Outcome outcome;
    try {
      outcome = study::run(batch->study, {options.jobs, options.resume, options.rank_timeout_s}, session);
    } catch (const study::RankLost& e) {  // its "--resume" names the batch: the tuning resumes from OUT
      throw study::RankLost(std::string(e.what()) + "\n(the tuning: aerie-ceopt landing ... --resume " +
                            std::filesystem::path(options.dir).parent_path().string() + ")");
    }
    if (outcome.failed)
      throw std::runtime_error("aerie-ceopt: " + std::to_string(outcome.failed) + " landings of " + options.dir + name +
                               " failed (said above); the tuning cannot go on without their costs");
    return batch->runs;
  };
}

void end_landing_studies(const study::Session& session) {
  if (session.distributed()) session.broadcast("");
}

void serve_landing_studies(const LandingTuning& problem, const study::Session& session) {
  for (;;) {
    const std::string bytes = session.broadcast("");
    if (bytes.empty()) return;
    const auto batch = make_batch(problem, bytes, "");
    study::run(batch->study, study::Options{}, session);
  }
}

}  // namespace aerie::ceopt
