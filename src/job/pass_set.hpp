// A set of pass (sample) indices, as disjoint half-open ranges [begin, end) in increasing order:
// which passes a film holds. A render is the set of its passes: the processes of one render
// take disjoint parts of it, a checkpoint records the part that is done, `merge` refuses two
// renders of one seed whose sets overlap. Text form (checkpoints, EXR metadata): "0-63,128-255"
// with inclusive ends, "" for the empty set.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pathlab {

struct PassRange {
    uint64_t begin = 0, end = 0;  // [begin, end)
    uint64_t size() const { return end - begin; }
    bool operator==(const PassRange&) const = default;
};

class PassSet {
public:
    PassSet() = default;
    static PassSet range(uint64_t begin, uint64_t end);

    void insert(uint64_t begin, uint64_t end);
    void insert(const PassSet& other);
    bool empty() const { return ranges_.empty(); }
    uint64_t count() const;
    const std::vector<PassRange>& ranges() const { return ranges_; }
    bool contains(const PassSet& other) const;
    bool intersects(const PassSet& other) const;
    // The passes of this set not in `other`.
    PassSet minus(const PassSet& other) const;
    // The first n passes of the set (all of it when it has fewer).
    PassSet first(uint64_t n) const;
    // Part `part` of `parts` of the set, in order: contiguous in the set's order, the sizes
    // differing by at most one (the lower parts get the larger ones).
    PassSet part(int part, int parts) const;
    // One past the largest pass (0 for the empty set); the smallest pass (0 for the empty set).
    uint64_t end() const { return ranges_.empty() ? 0 : ranges_.back().end; }
    uint64_t begin() const { return ranges_.empty() ? 0 : ranges_.front().begin; }

    std::string to_string() const;
    // The text form; nullopt when malformed (not increasing, overlapping, not numbers).
    static std::optional<PassSet> parse(const std::string& text);

    bool operator==(const PassSet&) const = default;

private:
    std::vector<PassRange> ranges_;
};

}  // namespace pathlab
