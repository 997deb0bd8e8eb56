"""The file formats: MCAP bags written and read (mcap_bag, reader), their integrity and salvage
(integrity), the site stored in a bag (site_record), detector and station CSVs (csv_io,
measured_csv), a bag of passes (passes_bag), output folders and their retention."""
