"""Job runners: one drawing through the pipeline, batches, atomic output."""
