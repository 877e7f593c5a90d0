// Ceres' own log lines kept off the terminal (solver_log.hpp).
#include "solver_log.hpp"

#include <algorithm>
#include <cstddef>
#include <mutex>
#include <utility>

#include <glog/logging.h>

namespace roughscope::detail {
namespace {

thread_local std::vector<std::string>* t_solver_log = nullptr;

class SolverLogSink final : public google::LogSink {
  public:
    void send(google::LogSeverity /*severity*/, const char* /*full_filename*/,
              const char* /*base_filename*/, int /*line*/, const google::LogMessageTime& /*time*/,
              const char* message, std::size_t message_len) override {
        if (t_solver_log != nullptr) t_solver_log->emplace_back(message, message_len);
    }
};

void quiet_solver_logging() {
    static std::once_flag once;
    std::call_once(once, [] {
        if (!google::IsGoogleLoggingInitialized()) {
            google::InitGoogleLogging("roughscope");
            for (int severity = google::GLOG_INFO; severity < google::NUM_SEVERITIES; ++severity)
                google::SetLogDestination(severity, "");
            FLAGS_stderrthreshold = google::GLOG_FATAL;
        }
        static SolverLogSink sink;
        google::AddLogSink(&sink);
    });
}

}  // namespace

SolverLogCapture::SolverLogCapture() : previous_(t_solver_log) {
    quiet_solver_logging();
    t_solver_log = &lines_;
}

SolverLogCapture::~SolverLogCapture() { t_solver_log = previous_; }

std::string SolverLogCapture::summary() const {
    std::vector<std::pair<std::string, int>> distinct;
    for (const std::string& line : lines_) {
        auto it = std::find_if(distinct.begin(), distinct.end(),
                               [&](const auto& d) { return d.first == line; });
        if (it == distinct.end())
            distinct.emplace_back(line, 1);
        else
            ++it->second;
    }
    std::string out;
    for (const auto& [line, count] : distinct) {
        out += out.empty() ? "; solver log: " : "; ";
        out += line;
        if (count > 1) out += " (" + std::to_string(count) + " times)";
    }
    return out;
}

}  // namespace roughscope::detail
