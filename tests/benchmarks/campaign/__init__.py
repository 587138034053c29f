"""The validation-campaign studies: a stated truth recovered, a model-form error found, interval coverage
over noise seeds, tied parameters reported as such (``docs/rigdata.md``, "What the campaign shows")."""
