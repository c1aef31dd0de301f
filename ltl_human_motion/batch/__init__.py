"""Motion datasets at scale: many verified motions from a specs file (issue 8).

``run_batch`` derives every item from (global seed, item index), runs items on a local
process pool or a Dask distributed cluster, writes each result atomically and resumes a
killed run; ``open_dataset`` reads the result for training pipelines. Core package: no
ROS; Dask and tqdm are imported only when used.
"""

from ltl_human_motion.batch.items import (
    ItemParams,
    cell_for_item,
    derive_item,
    validate_against_cell,
)
from ltl_human_motion.batch.reader import (
    CorruptDatasetError,
    MotionDataset,
    MotionItem,
    deterministic_record,
    open_dataset,
)
from ltl_human_motion.batch.runner import BatchSummary, make_job, run_batch
from ltl_human_motion.batch.specs import (
    BatchConfigError,
    BatchSpecs,
    Jitter,
    SpecEntry,
    load_specs,
    specs_from_yaml,
)
from ltl_human_motion.batch.store import (
    DATASET_FORMAT,
    DATASET_VERSION,
    BatchOutputError,
    DatasetStore,
)
from ltl_human_motion.batch.worker import (
    ARRAY_NAMES,
    BatchJob,
    ItemResult,
    motion_sha256,
    run_item,
)

__all__ = [
    "ARRAY_NAMES",
    "DATASET_FORMAT",
    "DATASET_VERSION",
    "BatchConfigError",
    "BatchJob",
    "BatchOutputError",
    "BatchSpecs",
    "BatchSummary",
    "CorruptDatasetError",
    "DatasetStore",
    "ItemParams",
    "ItemResult",
    "Jitter",
    "MotionDataset",
    "MotionItem",
    "SpecEntry",
    "cell_for_item",
    "derive_item",
    "deterministic_record",
    "load_specs",
    "make_job",
    "motion_sha256",
    "open_dataset",
    "run_batch",
    "run_item",
    "specs_from_yaml",
    "validate_against_cell",
]
