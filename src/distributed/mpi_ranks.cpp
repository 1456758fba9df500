#include "distributed/mpi_ranks.hpp"

#include <mpi.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace pathlab {
namespace {

// MPI's reduction of films: the exact merge of two pixels' accumulators, commutative and
// associative, so whatever tree MPI reduces along gives the same bits.
extern "C" void merge_pixel_sums(void* in, void* inout, int* count, MPI_Datatype*) {
    const auto* a = static_cast<const PixelSums*>(in);
    auto* b = static_cast<PixelSums*>(inout);
    for (int i = 0; i < *count; ++i) b[i].merge(a[i]);
}

class MpiRanks final : public RankGroup {
public:
    MpiRanks() {
        MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
        MPI_Comm_size(MPI_COMM_WORLD, &size_);
        char host[MPI_MAX_PROCESSOR_NAME];
        int len = 0;
        MPI_Get_processor_name(host, &len);
        name_ = fmt::format("rank {} ({})", rank_, std::string(host, size_t(len)));
        MPI_Type_contiguous(int(sizeof(PixelSums)), MPI_BYTE, &pixel_type_);
        MPI_Type_commit(&pixel_type_);
        MPI_Op_create(merge_pixel_sums, /*commute=*/1, &merge_op_);
    }
    ~MpiRanks() override {
        MPI_Op_free(&merge_op_);
        MPI_Type_free(&pixel_type_);
    }

    int rank() const override { return rank_; }
    int size() const override { return size_; }
    std::string name() const override { return name_; }

    void all_max(std::span<double> values) override {
        MPI_Allreduce(MPI_IN_PLACE, values.data(), int(values.size()), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    }

    std::vector<double> gather(std::span<const double> values) override {
        std::vector<double> out(rank_ == 0 ? values.size() * size_t(size_) : 0);
        MPI_Gather(values.data(), int(values.size()), MPI_DOUBLE, out.data(), int(values.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
        return out;
    }

    std::vector<std::string> gather_text(const std::string& text) override {
        int len = int(text.size());
        std::vector<int> lens(rank_ == 0 ? size_t(size_) : 0), offsets(lens.size());
        MPI_Gather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
        int total = 0;
        for (size_t r = 0; r < lens.size(); ++r) offsets[r] = total, total += lens[r];
        std::string all(size_t(total), '\0');
        MPI_Gatherv(text.data(), len, MPI_CHAR, all.data(), lens.data(), offsets.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
        std::vector<std::string> out;
        for (size_t r = 0; r < lens.size(); ++r) out.push_back(all.substr(size_t(offsets[r]), size_t(lens[r])));
        return out;
    }

    void broadcast_text(std::string& text) override {
        uint64_t len = text.size();
        MPI_Bcast(&len, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
        text.resize(len);
        MPI_Bcast(text.data(), int(len), MPI_CHAR, 0, MPI_COMM_WORLD);
    }

    std::vector<std::string> all_gather(const std::string& bytes) override {
        int len = int(bytes.size());
        std::vector<int> lens(static_cast<size_t>(size_)), offsets(static_cast<size_t>(size_));
        MPI_Allgather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, MPI_COMM_WORLD);
        int64_t total = 0;
        for (size_t r = 0; r < lens.size(); ++r) offsets[r] = int(total), total += lens[r];
        if (total > INT32_MAX) throw std::runtime_error("all_gather: more than 2 GiB from all ranks together");
        std::string all(size_t(total), '\0');
        MPI_Allgatherv(bytes.data(), len, MPI_CHAR, all.data(), lens.data(), offsets.data(), MPI_CHAR, MPI_COMM_WORLD);
        std::vector<std::string> out;
        for (size_t r = 0; r < lens.size(); ++r) out.push_back(all.substr(size_t(offsets[r]), size_t(lens[r])));
        return out;
    }

    void abort(int code) override { MpiSession::abort(code); }

    void reduce_film(const Film& film, size_t chunk_pixels, const ChunkUse& use) override {
        std::vector<PixelSums> sum(rank_ == 0 ? std::min(chunk_pixels, film.pixel_count()) : 0);
        for (size_t first = 0; first < film.pixel_count(); first += chunk_pixels) {
            const size_t n = std::min(chunk_pixels, film.pixel_count() - first);
            MPI_Reduce(film.data() + first, sum.data(), int(n), pixel_type_, merge_op_, 0, MPI_COMM_WORLD);
            if (rank_ == 0) use(first, sum.data(), n);
        }
    }

private:
    int rank_ = 0, size_ = 1;
    std::string name_;
    MPI_Datatype pixel_type_;
    MPI_Op merge_op_;
};

}  // namespace

MpiSession::MpiSession() : ranks_(std::make_unique<MpiRanks>()) {}

MpiSession::~MpiSession() {
    ranks_.reset();
    MPI_Finalize();
}

std::unique_ptr<MpiSession> MpiSession::join(int& argc, char**& argv) {
    bool launched = std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK") || std::getenv("PMI_RANK");
    if (const char* force = std::getenv("PATHLAB_MPI")) launched = std::strcmp(force, "1") == 0;
    if (!launched) return nullptr;
    int provided = 0;
    // Only the main thread calls MPI (the render's worker threads never do).
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    return std::unique_ptr<MpiSession>(new MpiSession());
}

void MpiSession::abort(int code) {
    MPI_Abort(MPI_COMM_WORLD, code);
    std::abort();
}

}  // namespace pathlab
