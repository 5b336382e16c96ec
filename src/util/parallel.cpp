// parallel.cpp — the helper threads of parallelFor (parallel.h).
#include "util/parallel.h"

#include <condition_variable>

namespace gdpt {
namespace {

// Threads that wait for a job; a job names how many of them may join it. The caller takes the
// pool for one job at a time (try_lock: a second caller runs without it).
class Pool {
public:
    explicit Pool(std::uint32_t threads) {
        for (std::uint32_t t = 0; t < threads; ++t) threads_.emplace_back([this] { serve(); });
    }
    ~Pool() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        wake_.notify_all();
        for (std::thread& t : threads_) t.join();
    }
    Pool(const Pool&) = delete;
    Pool& operator=(const Pool&) = delete;

    bool run(std::uint32_t helpers, const std::function<void()>& work) {
        // Inside a job (a helper's, or the caller's own loop body): not the pool again.
        if (helpers > threads_.size() || inJob_) return false;
        std::unique_lock<std::mutex> owner(use_, std::try_to_lock);
        if (!owner.owns_lock()) return false;
        inJob_ = true;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            job_ = &work;
            open_ = helpers;
        }
        wake_.notify_all();
        work();
        std::unique_lock<std::mutex> lock(mutex_);
        open_ = 0;  // seats not taken by now are not needed: the work is shared by a counter
        done_.wait(lock, [&] { return running_ == 0; });
        job_ = nullptr;
        inJob_ = false;
        return true;
    }

private:
    void serve() {
        inJob_ = true;
        std::unique_lock<std::mutex> lock(mutex_);
        while (true) {
            wake_.wait(lock, [&] { return stop_ || open_ > 0; });
            if (stop_) return;
            --open_;
            ++running_;
            const std::function<void()>* job = job_;
            lock.unlock();
            (*job)();
            lock.lock();
            if (--running_ == 0) done_.notify_all();
        }
    }

    std::mutex use_;    // held by the caller whose job the pool runs
    std::mutex mutex_;  // guards what follows
    std::condition_variable wake_, done_;
    const std::function<void()>* job_ = nullptr;
    std::uint32_t open_ = 0;     // helpers that may still join the job
    std::uint32_t running_ = 0;  // helpers running it
    bool stop_ = false;
    std::vector<std::thread> threads_;
    static thread_local bool inJob_;  // this thread runs a job of the pool (helper or caller)
};

thread_local bool Pool::inJob_ = false;

}  // namespace

bool runOnPool(std::uint32_t helpers, const std::function<void()>& work) {
    static Pool pool(defaultThreads() - 1);
    return pool.run(helpers, work);
}

}  // namespace gdpt
