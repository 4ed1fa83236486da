"""local_step"""
